// The gait expression language: parse, compile, evaluate. A program that
// compiles must print back (to_string) to a program that evaluates
// bit-identically, and must evaluate within its declared stack depth.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "animrt/controllers/gait/expression.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using animrt::Expression;
  Expression e;
  try {
    e = Expression::compile(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const animrt::ExpressionError& error) {
    if (error.column() < 1 || static_cast<std::size_t>(error.column()) > size + 1) std::abort();
    return 0;
  }
  if (e.stack_depth() < 1 || e.stack_depth() > Expression::kMaxStackDepth) std::abort();
  Expression again;
  try {
    again = Expression::compile(e.to_string());
  } catch (const animrt::ExpressionError&) {
    std::abort();  // to_string must print something that compiles
  }
  for (double t : {0.0, 0.25, -1.5, 3.0e3, 1.0e-9}) {
    const double a = e.eval(t), b = again.eval(t);
    if (std::memcmp(&a, &b, sizeof a) != 0 && !(std::isnan(a) && std::isnan(b))) std::abort();
  }
  return 0;
}

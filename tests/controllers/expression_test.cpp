#include "animrt/controllers/gait/expression.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "animrt/core/joint.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

double eval(const std::string& text, double t) { return Expression::compile(text).eval(t); }

// Keeps the compiler from folding libm calls at build time (with a
// different rounding than the run-time libm the evaluator uses).
double opaque(double v) {
  volatile double x = v;
  return x;
}

TEST(Expression, Numbers) {
  EXPECT_EQ(eval("2", 0), 2.0);
  EXPECT_EQ(eval("6.97", 0), 6.97);
  EXPECT_EQ(eval("1e-3", 0), 1e-3);
  EXPECT_EQ(eval("2.5E+2", 0), 250.0);
  EXPECT_EQ(eval(".5", 0), 0.5);
  EXPECT_EQ(eval("5.", 0), 5.0);
  EXPECT_EQ(eval("0.1", 0), 0.1);  // parsed exactly, as the C++ literal
  EXPECT_EQ(eval("123456789012345678901234567890", 0), 123456789012345678901234567890.0);
}

TEST(Expression, VariableAndWhitespace) {
  EXPECT_EQ(eval("t", 3.5), 3.5);
  EXPECT_EQ(eval(" \t1 +\n t\r\n", 2.0), 3.0);
  EXPECT_EQ(eval("2*t", -4.0), -8.0);
}

TEST(Expression, Precedence) {
  EXPECT_EQ(eval("1 + 2*3", 0), 7.0);
  EXPECT_EQ(eval("2*3 + 1", 0), 7.0);
  EXPECT_EQ(eval("(1 + 2)*3", 0), 9.0);
  EXPECT_EQ(eval("t + 2*t", 1.0), 3.0);
  EXPECT_EQ(eval("t - 6/3", 5.0), 3.0);
  EXPECT_EQ(eval("t*2 + t/2", 4.0), 10.0);
}

TEST(Expression, LeftAssociativity) {
  EXPECT_EQ(eval("t - 2 - 3", 1.0), -4.0);
  EXPECT_EQ(eval("t - (2 - 3)", 1.0), 2.0);
  EXPECT_EQ(eval("t / 4 / 2", 16.0), 2.0);
  EXPECT_EQ(eval("t / (4 / 2)", 16.0), 8.0);
  EXPECT_EQ(eval("1 - t + 3", 2.0), 2.0);
  // Rounding shows the grouping: at 2^53, (t + 1) + 2 != t + (1 + 2).
  const double big = 9007199254740992.0;
  EXPECT_EQ(eval("t + 1 + 2", big), (big + 1.0) + 2.0);
  EXPECT_EQ(eval("t + (1 + 2)", big), big + 3.0);
  EXPECT_NE(eval("t + 1 + 2", big), eval("t + (1 + 2)", big));
}

TEST(Expression, UnaryMinus) {
  EXPECT_EQ(eval("-t", 2.0), -2.0);
  EXPECT_EQ(eval("- t", 2.0), -2.0);
  EXPECT_EQ(eval("--t", 2.0), 2.0);
  EXPECT_EQ(eval("-(-t)", 2.0), 2.0);
  EXPECT_EQ(eval("2*-t", 3.0), -6.0);
  EXPECT_EQ(eval("-t*3", 2.0), -6.0);
  EXPECT_EQ(eval("-(1 + t)", 2.0), -3.0);
  EXPECT_EQ(eval("1 - -1", 0), 2.0);
  EXPECT_EQ(eval("6.97 + -1.07", 0), 6.97 + -1.07);
  EXPECT_EQ(eval("t + -1.07", 1.0), 1.0 - 1.07);
  EXPECT_EQ(eval("-1.07", 0), -1.07);
  EXPECT_TRUE(std::signbit(eval("-0", 0)));
}

TEST(Expression, ProtectedDivision) {
  EXPECT_EQ(eval("t / 0", 5.0), 1.0);
  EXPECT_EQ(eval("t / -0", 5.0), 1.0);
  EXPECT_EQ(eval("0 / 0", 0), 1.0);
  EXPECT_EQ(eval("t / (t - t)", 7.0), 1.0);
  EXPECT_EQ(eval("1 / t", 0.0), 1.0);
  EXPECT_EQ(eval("1 / t", 4.0), 0.25);
  EXPECT_EQ(eval("0 / t", 0.0), 1.0);
  EXPECT_EQ(eval("3 / 0 * t", 2.0), 2.0);
  EXPECT_EQ(eval("t / 1e-300", 1e-10), 1e-10 / 1e-300);
}

TEST(Expression, SinCosPi) {
  EXPECT_EQ(eval("PI", 0), kPi);
  EXPECT_EQ(eval("cos(0)", 0), 1.0);
  EXPECT_EQ(eval("sin(t)", 0.3), std::sin(opaque(0.3)));
  EXPECT_EQ(eval("cos(t)", 0.3), std::cos(opaque(0.3)));
  EXPECT_EQ(eval("sin(PI/2)", 0), std::sin(opaque(kPi) / 2.0));
  EXPECT_EQ(eval("sin(2*PI*t)", 0.125), std::sin(opaque(2.0 * kPi) * 0.125));
  EXPECT_EQ(eval("cos(sin(t))", 1.0), std::cos(std::sin(opaque(1.0))));
  EXPECT_EQ(eval("sin ( t )", 0.5), std::sin(opaque(0.5)));
}

// The paper's seed curve against the same formula in C++, same order.
TEST(Expression, SeedCurve) {
  const Expression e =
      Expression::compile("6.97 + 7.7*sin(1*2*PI*t + -1.07) + 2.56*sin(2*2*PI*t + 2.97)");
  for (double t : {0.0, 0.1, 0.25, 0.5, 0.77, 1.0, 12.3}) {
    const double x = opaque(t);
    const double want = 6.97 + 7.7 * std::sin(1.0 * 2.0 * kPi * x + -1.07) +
                        2.56 * std::sin(2.0 * 2.0 * kPi * x + 2.97);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(e.eval(t)), std::bit_cast<std::uint64_t>(want))
        << "t = " << t;
  }
}

TEST(Expression, FoldsOnlyConstantSubtrees) {
  EXPECT_EQ(Expression::compile("2 + 3*4").size(), 1u);
  EXPECT_EQ(Expression::compile("sin(PI/2) * cos(0)").size(), 1u);
  EXPECT_EQ(Expression::compile("1*2*PI*t").size(), 1u);  // (1*2*PI) then one k*t
  EXPECT_EQ(Expression::compile("1*2*PI*t").to_string(), "6.283185307179586*t");
  EXPECT_EQ(Expression::compile("t + 1 + 2").size(), 2u);  // t + 1 is not constant
  EXPECT_EQ(Expression::compile("t + (1 + 2)").size(), 1u);
}

TEST(Expression, NonFiniteConstantsStayUnfolded) {
  const Expression e = Expression::compile("1e308 * 10");
  EXPECT_TRUE(std::isinf(e.eval(0)));
  EXPECT_EQ(e.to_string(), "1e+308*10");
  EXPECT_TRUE(std::isnan(eval("sin(1e308*10)", 0)));
}

TEST(Expression, DefaultIsZero) {
  const Expression e;
  EXPECT_EQ(e.eval(3.0), 0.0);
  EXPECT_EQ(e.to_string(), "0");
}

TEST(Expression, ToStringKeepsTheTree) {
  EXPECT_EQ(Expression::compile("t - (t - t)").to_string(), "t - (t - t)");
  EXPECT_EQ(Expression::compile("(t - t) - t").to_string(), "t - t - t");
  EXPECT_EQ(Expression::compile("t + (t + t)").to_string(), "t + (t + t)");
  EXPECT_EQ(Expression::compile("t / (t * t)").to_string(), "t/(t*t)");
  EXPECT_EQ(Expression::compile("(t + 1) * -t").to_string(), "(t + 1)*-t");
  EXPECT_EQ(Expression::compile("-(t * t)").to_string(), "-(t*t)");
  EXPECT_EQ(Expression::compile("-(-t)").to_string(), "- -t");
  EXPECT_EQ(Expression::compile("t - -1.07").to_string(), "t - -1.07");
  EXPECT_EQ(Expression::compile("cos(t)*sin(t)").to_string(), "cos(t)*sin(t)");
}

TEST(Expression, ToStringRoundTripsBitForBit) {
  for (const char* text :
       {"6.97 + 7.7*sin(1*2*PI*t + -1.07) + 2.56*sin(2*2*PI*t + 2.97)", "0.1 + 0.2*t",
        "t / (0.3 - t) - 1/3", "-(t*1e-320) + 5e-324", "sin(t)/cos(t) * -0", "1e308*10*t"}) {
    const Expression e = Expression::compile(text);
    const Expression back = Expression::compile(e.to_string());
    EXPECT_EQ(back.to_string(), e.to_string()) << text;
    EXPECT_EQ(back.size(), e.size()) << text;
    for (double t : {0.0, 0.3, -2.5, 0.999, 1e6}) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(back.eval(t)), std::bit_cast<std::uint64_t>(e.eval(t)))
          << text << " at " << t;
    }
  }
}

// Found by the gait_expression fuzz harness ("1 - " then 163 unary minuses
// before "(t)/(t*t-0)..."): to_string printed each negation of a negation
// with parentheses, twice the nesting of the source, and the printed text
// no longer compiled past 128 minuses.
TEST(Expression, LongRunOfUnaryMinusesPrintsBackToACompilableProgram) {
  const std::string text = "1 - " + std::string(200, '-') + "(t)/(t*t-0)";
  const Expression e = Expression::compile(text);
  const Expression back = Expression::compile(e.to_string());
  EXPECT_EQ(back.to_string(), e.to_string());
  for (double t : {0.5, -3.0})
    EXPECT_EQ(std::bit_cast<std::uint64_t>(back.eval(t)), std::bit_cast<std::uint64_t>(e.eval(t)))
        << t;
}

struct ErrorCase {
  const char* text;
  int column;
  const char* message;
};

TEST(ExpressionError, ReportsColumnAndMessage) {
  const ErrorCase cases[] = {
      {"", 1, "empty expression"},
      {"   ", 1, "empty expression"},
      {"1 + )", 5, "unexpected ')'"},
      {"()", 2, "unexpected ')'"},
      {"sin()", 5, "unexpected ')'"},
      {"* t", 1, "unexpected '*'"},
      {"1 +", 4, "unexpected end of expression"},
      {"2 t", 3, "unexpected 't'"},
      {"(t))", 4, "unexpected ')'"},
      {"sin(2*PI*t + 1", 15, "expected ')' to close '(' at column 4"},
      {"(1 + (2 * t)", 13, "expected ')' to close '(' at column 1"},
      {"(1 + 2 t)", 8, "expected ')' to close '(' at column 1"},
      {"2 * x", 5, "unknown name 'x' (expected t, PI, sin, cos)"},
      {"pi", 1, "unknown name 'pi' (expected t, PI, sin, cos)"},
      {"tan(t)", 1, "unknown name 'tan' (expected t, PI, sin, cos)"},
      {"sin t", 5, "expected '(' after 'sin'"},
      {"cos", 4, "expected '(' after 'cos'"},
      {"1e999", 1, "number out of range"},
      {"t + 1e-400", 5, "number out of range"},
      {"t + 1e+", 5, "malformed number '1e+' (expected digits in the exponent)"},
      {"1 # 2", 3, "unexpected character '#'"},
      {"t . 2", 3, "unexpected character '.'"},
  };
  for (const auto& c : cases) {
    try {
      (void)Expression::compile(c.text);
      ADD_FAILURE() << "no error for \"" << c.text << "\"";
    } catch (const ExpressionError& e) {
      EXPECT_EQ(e.column(), c.column) << c.text;
      EXPECT_EQ(e.message(), c.message) << c.text;
      EXPECT_EQ(std::string(e.what()), "column " + std::to_string(c.column) + ": " + c.message);
    }
  }
}

TEST(ExpressionError, RelatedColumnIsSeparate) {
  try {
    (void)Expression::compile("sin(t");
    FAIL();
  } catch (const ExpressionError& e) {
    EXPECT_EQ(e.column(), 6);
    EXPECT_EQ(e.related_column(), 4);
    EXPECT_EQ(e.detail(), "expected ')' to close '('");
  }
}

// sin(t) + (sin(t) + (... + sin(t))) keeps one value per level on the stack.
std::string right_nested(int n) {
  std::string s;
  for (int i = 1; i < n; ++i) s += "sin(t) + (";
  s += "sin(t)";
  s += std::string(static_cast<std::size_t>(n - 1), ')');
  return s;
}

TEST(ExpressionError, TooDeepForTheStack) {
  const Expression ok = Expression::compile(right_nested(Expression::kMaxStackDepth));
  EXPECT_EQ(ok.stack_depth(), Expression::kMaxStackDepth);
  const double s = std::sin(opaque(0.5));
  double sum = s;
  for (int i = 1; i < Expression::kMaxStackDepth; ++i) sum = s + sum;
  EXPECT_EQ(ok.eval(0.5), sum);

  const std::string text = right_nested(Expression::kMaxStackDepth + 1);
  try {
    (void)Expression::compile(text);
    FAIL();
  } catch (const ExpressionError& e) {
    // The last sin(t): its t is the push that does not fit.
    EXPECT_EQ(e.column(), static_cast<int>(text.rfind('t')) + 1);
    EXPECT_EQ(e.message(),
              "expression too deep: needs more than 64 values on the evaluation stack");
  }
}

TEST(ExpressionError, TooDeeplyNested) {
  const int n = Expression::kMaxNesting;
  EXPECT_EQ(eval(std::string(n, '(') + "t" + std::string(n, ')'), 2.0), 2.0);
  EXPECT_EQ(eval(std::string(n, '-') + "t", 2.0), 2.0);  // n is even
  try {
    (void)Expression::compile(std::string(n + 1, '(') + "t" + std::string(n + 1, ')'));
    FAIL();
  } catch (const ExpressionError& e) {
    EXPECT_EQ(e.column(), n + 1);
    EXPECT_EQ(e.message(), "expression nested too deeply (more than 256 levels)");
  }
}

TEST(ExpressionAlloc, CounterSeesAllocations) {
  static void* volatile sink = nullptr;
  test::AllocationCounter counter;
  sink = ::operator new(16);
  ::operator delete(sink);
  std::string s(100, 'x');  // beyond the small-string buffer
  sink = s.data();
  EXPECT_GE(counter.count(), 2);
}

TEST(ExpressionAlloc, EvalDoesNotAllocate) {
  const Expression e = Expression::compile(
      "6.97 + 7.7*sin(1*2*PI*t + -1.07) + 2.56*sin(2*2*PI*t + 2.97) - t/(t - 0.5) + cos(t)*-t");
  double sum = 0.0;
  test::AllocationCounter counter;
  for (int i = 0; i < 1000; ++i) sum += e.eval(i * 0.001);
  EXPECT_EQ(counter.count(), 0);
  EXPECT_TRUE(std::isfinite(sum));
}

}  // namespace
}  // namespace animrt

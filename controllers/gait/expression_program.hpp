#pragma once
// Opcodes of a compiled Expression, shared by the compiler and the evaluator
// (private to controllers/gait).
//
// The program is postfix. A binary instruction names where its operands come
// from, so that leaves fuse into their operator and the common shapes
// (k*t, x + k, k*sin(...)) run as one dispatch each: S is the running value
// (top of the stack), P the value below it (popped), K the immediate, T the
// variable t. Forms without S push their result.

#include <cmath>
#include <cstdint>

namespace animrt::expr {

enum Op : std::uint8_t {
  kConst = 0,  // push k
  kT,          // push t
  kNeg,
  kSin,
  kCos,
  kBinaryBase = 8,  // then 8 forms for each of the 4 operators
};

enum Binary : std::uint8_t { kAdd, kSub, kMul, kDiv };
enum Form : std::uint8_t { kPS, kSK, kKS, kST, kTS, kKT, kTK, kTT };
constexpr int kForms = 8;

constexpr std::uint8_t binary_op(Binary b, Form f) {
  return static_cast<std::uint8_t>(kBinaryBase + b * kForms + f);
}
constexpr bool is_binary(std::uint8_t op) { return op >= kBinaryBase; }
constexpr Binary binary_of(std::uint8_t op) {
  return static_cast<Binary>((op - kBinaryBase) / kForms);
}
constexpr Form form_of(std::uint8_t op) { return static_cast<Form>((op - kBinaryBase) % kForms); }

// Values pushed (+1), popped (-1) or neither (0) by an instruction.
constexpr int stack_effect(std::uint8_t op) {
  if (op == kConst || op == kT) return 1;
  if (!is_binary(op)) return 0;
  const Form f = form_of(op);
  if (f == kPS) return -1;
  return (f == kKT || f == kTK || f == kTT) ? 1 : 0;
}

// The one definition of each operation, used by constant folding and by the
// evaluator alike so that both round identically.
inline double add(double a, double b) { return a + b; }
inline double sub(double a, double b) { return a - b; }
inline double mul(double a, double b) { return a * b; }
// Protected division: 1 when the divisor is exactly zero (either sign).
inline double pdiv(double a, double b) { return b == 0.0 ? 1.0 : a / b; }

inline double apply(Binary b, double x, double y) {
  switch (b) {
    case kAdd:
      return add(x, y);
    case kSub:
      return sub(x, y);
    case kMul:
      return mul(x, y);
    case kDiv:
      return pdiv(x, y);
  }
  return 0.0;
}

inline double apply_unary(std::uint8_t op, double x) {
  switch (op) {
    case kNeg:
      return -x;
    case kSin:
      return std::sin(x);
    case kCos:
      return std::cos(x);
    default:
      return x;
  }
}

}  // namespace animrt::expr

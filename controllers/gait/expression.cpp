// Evaluating and printing compiled expressions.

#include "animrt/controllers/gait/expression.hpp"

#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "expression_program.hpp"

namespace animrt {

using expr::add;
using expr::Binary;
using expr::binary_of;
using expr::binary_op;
using expr::form_of;
using expr::kAdd;
using expr::kConst;
using expr::kCos;
using expr::kDiv;
using expr::kKS;
using expr::kKT;
using expr::kMul;
using expr::kNeg;
using expr::kPS;
using expr::kSin;
using expr::kSK;
using expr::kST;
using expr::kSub;
using expr::kT;
using expr::kTK;
using expr::kTS;
using expr::kTT;
using expr::mul;
using expr::pdiv;
using expr::sub;

ExpressionError::ExpressionError(int column, std::string detail, int related_column)
    : std::runtime_error(
          "column " + std::to_string(column) + ": " + detail +
          (related_column > 0 ? " at column " + std::to_string(related_column) : std::string())),
      column_(column),
      related_column_(related_column),
      detail_(std::move(detail)) {}

std::string ExpressionError::message() const {
  if (related_column_ <= 0) return detail_;
  return detail_ + " at column " + std::to_string(related_column_);
}

Expression::Expression() : code_{Instr{kConst, 0.0}} {}

// One case per operand form of a binary operator; `fn` is one of the
// functions in expression_program.hpp, shared with constant folding.
#define ANIMRT_BINARY_CASES(B, fn) \
  case binary_op(B, kPS):          \
    --sp;                          \
    acc = fn(*sp, acc);            \
    break;                         \
  case binary_op(B, kSK):          \
    acc = fn(acc, in.k);           \
    break;                         \
  case binary_op(B, kKS):          \
    acc = fn(in.k, acc);           \
    break;                         \
  case binary_op(B, kST):          \
    acc = fn(acc, t);              \
    break;                         \
  case binary_op(B, kTS):          \
    acc = fn(t, acc);              \
    break;                         \
  case binary_op(B, kKT):          \
    *sp++ = acc;                   \
    acc = fn(in.k, t);             \
    break;                         \
  case binary_op(B, kTK):          \
    *sp++ = acc;                   \
    acc = fn(t, in.k);             \
    break;                         \
  case binary_op(B, kTT):          \
    *sp++ = acc;                   \
    acc = fn(t, t);                \
    break;

double Expression::eval(double t) const noexcept {
  // The running value lives in `acc`; `stack` holds the values below it
  // (the first push stores a dummy, so depth_ slots suffice).
  double stack[kMaxStackDepth];
  double* sp = stack;
  double acc = 0.0;
  for (const Instr& in : code_) {
    switch (in.op) {
      case kConst:
        *sp++ = acc;
        acc = in.k;
        break;
      case kT:
        *sp++ = acc;
        acc = t;
        break;
      case kNeg:
        acc = -acc;
        break;
      case kSin:
        acc = std::sin(acc);
        break;
      case kCos:
        acc = std::cos(acc);
        break;
        ANIMRT_BINARY_CASES(kAdd, add)
        ANIMRT_BINARY_CASES(kSub, sub)
        ANIMRT_BINARY_CASES(kMul, mul)
        ANIMRT_BINARY_CASES(kDiv, pdiv)
      default:
        break;
    }
  }
  return acc;
}

#undef ANIMRT_BINARY_CASES

namespace {

// Precedence of what a piece of text is, for deciding on parentheses.
constexpr int kPrecSum = 1;
constexpr int kPrecProduct = 2;
constexpr int kPrecUnary = 3;
constexpr int kPrecAtom = 4;

struct Piece {
  std::string text;
  int prec;
};

// Shortest text that reads back as exactly the same double.
Piece number_piece(double k) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, k);
  (void)ec;  // 32 bytes always hold a double
  return {std::string(buf, end), std::signbit(k) ? kPrecUnary : kPrecAtom};
}

Piece t_piece() { return {"t", kPrecAtom}; }

std::string wrap(const Piece& p, bool parens) { return parens ? "(" + p.text + ")" : p.text; }

Piece binary_piece(Binary b, const Piece& l, const Piece& r) {
  static const char* const kSymbol[] = {" + ", " - ", "*", "/"};
  const int prec = (b == kAdd || b == kSub) ? kPrecSum : kPrecProduct;
  // Left associative: an equal-precedence right operand keeps its
  // parentheses, so the tree (and the rounding) is the same when read back.
  return {wrap(l, l.prec < prec) + kSymbol[b] + wrap(r, r.prec <= prec), prec};
}

}  // namespace

std::string Expression::to_string() const {
  std::vector<Piece> stack;
  for (const Instr& in : code_) {
    switch (in.op) {
      case kConst:
        stack.push_back(number_piece(in.k));
        continue;
      case kT:
        stack.push_back(t_piece());
        continue;
      case kNeg:
        // A negated negation prints as "- -x", not "-(-x)": the parentheses
        // would double the nesting, and a long run of unary minuses would
        // print past what compile() accepts (Expression::kMaxNesting).
        stack.back() = {(stack.back().prec == kPrecUnary ? "- " : "-") +
                            wrap(stack.back(), stack.back().prec < kPrecUnary),
                        kPrecUnary};
        continue;
      case kSin:
      case kCos:
        stack.back() = {(in.op == kSin ? "sin(" : "cos(") + stack.back().text + ")", kPrecAtom};
        continue;
      default:
        break;
    }
    const Binary b = binary_of(in.op);
    switch (form_of(in.op)) {
      case kPS: {
        Piece r = std::move(stack.back());
        stack.pop_back();
        stack.back() = binary_piece(b, stack.back(), r);
        break;
      }
      case kSK:
        stack.back() = binary_piece(b, stack.back(), number_piece(in.k));
        break;
      case kKS:
        stack.back() = binary_piece(b, number_piece(in.k), stack.back());
        break;
      case kST:
        stack.back() = binary_piece(b, stack.back(), t_piece());
        break;
      case kTS:
        stack.back() = binary_piece(b, t_piece(), stack.back());
        break;
      case kKT:
        stack.push_back(binary_piece(b, number_piece(in.k), t_piece()));
        break;
      case kTK:
        stack.push_back(binary_piece(b, t_piece(), number_piece(in.k)));
        break;
      case kTT:
        stack.push_back(binary_piece(b, t_piece(), t_piece()));
        break;
    }
  }
  return stack.empty() ? std::string("0") : stack.back().text;
}

}  // namespace animrt

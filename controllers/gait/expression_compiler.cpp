// Parsing and compiling the expression language (see expression.hpp): a
// recursive-descent parser that emits the postfix program directly, folding
// constant subtrees and fusing leaves into their operator as it goes.

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "animrt/controllers/gait/expression.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"
#include "expression_program.hpp"

namespace animrt {

using expr::apply;
using expr::apply_unary;
using expr::Binary;
using expr::binary_op;
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
using expr::Op;
using expr::stack_effect;

namespace {

enum class Kind { kNumber, kName, kPlus, kMinus, kStar, kSlash, kLParen, kRParen, kEnd };

struct Token {
  Kind kind = Kind::kEnd;
  std::size_t begin = 0;  // byte offsets into the text
  std::size_t end = 0;
  double number = 0.0;
};

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_name_char(char c) { return is_name_start(c) || is_digit(c); }

int column_of(std::size_t offset) { return static_cast<int>(offset) + 1; }

std::string quote_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7f) return std::string("'") + c + "'";
  static const char kHex[] = "0123456789abcdef";
  return std::string("byte 0x") + kHex[u >> 4] + kHex[u & 15];
}

}  // namespace

class ExpressionCompiler {
 public:
  explicit ExpressionCompiler(std::string_view text) : text_(text) {}

  Expression run() {
    std::size_t first = 0;
    while (first < text_.size() && is_space(text_[first])) ++first;
    if (first == text_.size()) throw ExpressionError(1, "empty expression");
    advance();
    parse_sum();
    if (tok_.kind != Kind::kEnd) unexpected();

    const int depth = check_depth(code_);
    return Expression(std::move(code_), depth);
  }

 private:
  // ---- lexing ----

  void advance() {
    std::size_t i = tok_.end;
    while (i < text_.size() && is_space(text_[i])) ++i;
    tok_ = Token{Kind::kEnd, i, i, 0.0};
    if (i == text_.size()) return;
    const char c = text_[i];
    auto single = [&](Kind kind) { tok_ = Token{kind, i, i + 1, 0.0}; };
    switch (c) {
      case '+':
        return single(Kind::kPlus);
      case '-':
        return single(Kind::kMinus);
      case '*':
        return single(Kind::kStar);
      case '/':
        return single(Kind::kSlash);
      case '(':
        return single(Kind::kLParen);
      case ')':
        return single(Kind::kRParen);
      default:
        break;
    }
    if (is_digit(c) || (c == '.' && i + 1 < text_.size() && is_digit(text_[i + 1]))) {
      return lex_number(i);
    }
    if (is_name_start(c)) {
      std::size_t j = i + 1;
      while (j < text_.size() && is_name_char(text_[j])) ++j;
      tok_ = Token{Kind::kName, i, j, 0.0};
      return;
    }
    throw ExpressionError(column_of(i), "unexpected character " + quote_char(c));
  }

  void lex_number(std::size_t i) {
    std::size_t j = i;
    while (j < text_.size() && is_digit(text_[j])) ++j;
    if (j < text_.size() && text_[j] == '.') {
      ++j;
      while (j < text_.size() && is_digit(text_[j])) ++j;
    }
    if (j < text_.size() && (text_[j] == 'e' || text_[j] == 'E')) {
      std::size_t k = j + 1;
      if (k < text_.size() && (text_[k] == '+' || text_[k] == '-')) ++k;
      if (k == text_.size() || !is_digit(text_[k])) {
        throw ExpressionError(column_of(i), "malformed number '" +
                                                std::string(text_.substr(i, k - i)) +
                                                "' (expected digits in the exponent)");
      }
      while (k < text_.size() && is_digit(text_[k])) ++k;
      j = k;
    }
    double value = 0.0;
    const char* b = text_.data() + i;
    const char* e = text_.data() + j;
    auto [ptr, ec] = std::from_chars(b, e, value);
    if (ec == std::errc::result_out_of_range)
      throw ExpressionError(column_of(i), "number out of range");
    if (ec != std::errc() || ptr != e) {
      throw ExpressionError(column_of(i), "malformed number '" + elide(std::string(b, e)) + "'");
    }
    tok_ = Token{Kind::kNumber, i, j, value};
  }

  std::string_view tok_text() const { return text_.substr(tok_.begin, tok_.end - tok_.begin); }
  int tok_column() const { return column_of(tok_.begin); }

  [[noreturn]] void unexpected() const {
    if (tok_.kind == Kind::kEnd)
      throw ExpressionError(tok_column(), "unexpected end of expression");
    throw ExpressionError(tok_column(), "unexpected '" + std::string(tok_text()) + "'");
  }

  // ---- parsing ----

  // Guards the recursion of '(', function calls and unary minus.
  struct Nest {
    explicit Nest(ExpressionCompiler& c) : c_(c) {
      if (++c_.nesting_ > Expression::kMaxNesting) {
        throw ExpressionError(c_.tok_column(), "expression nested too deeply (more than " +
                                                   std::to_string(Expression::kMaxNesting) +
                                                   " levels)");
      }
    }
    ~Nest() { --c_.nesting_; }
    Nest(const Nest&) = delete;
    Nest& operator=(const Nest&) = delete;
    ExpressionCompiler& c_;
  };

  void parse_sum() {
    parse_product();
    while (tok_.kind == Kind::kPlus || tok_.kind == Kind::kMinus) {
      const Binary b = tok_.kind == Kind::kPlus ? kAdd : kSub;
      const int col = tok_column();
      advance();
      const std::size_t right = code_.size();
      parse_product();
      emit_binary(b, right, col);
    }
  }

  void parse_product() {
    parse_unary();
    while (tok_.kind == Kind::kStar || tok_.kind == Kind::kSlash) {
      const Binary b = tok_.kind == Kind::kStar ? kMul : kDiv;
      const int col = tok_column();
      advance();
      const std::size_t right = code_.size();
      parse_unary();
      emit_binary(b, right, col);
    }
  }

  void parse_unary() {
    if (tok_.kind != Kind::kMinus) return parse_primary();
    Nest nest(*this);
    const int col = tok_column();
    advance();
    parse_unary();
    emit_unary(kNeg, col);
  }

  void parse_primary() {
    const int col = tok_column();
    switch (tok_.kind) {
      case Kind::kNumber:
        emit(kConst, tok_.number, col);
        advance();
        return;
      case Kind::kLParen: {
        Nest nest(*this);
        advance();
        parse_sum();
        expect_close(col);
        return;
      }
      case Kind::kName:
        return parse_name();
      default:
        unexpected();
    }
  }

  void parse_name() {
    const std::string_view name = tok_text();
    const int col = tok_column();
    if (name == "t") {
      emit(kT, 0.0, col);
      advance();
    } else if (name == "PI") {
      emit(kConst, kPi, col);
      advance();
    } else if (name == "sin" || name == "cos") {
      const Op op = name == "sin" ? kSin : kCos;
      const std::string fn(name);
      advance();
      if (tok_.kind != Kind::kLParen) {
        throw ExpressionError(tok_column(), "expected '(' after '" + elide(fn) + "'");
      }
      const int open = tok_column();
      Nest nest(*this);
      advance();
      parse_sum();
      expect_close(open);
      emit_unary(op, col);
    } else {
      throw ExpressionError(
          col, "unknown name '" + elide(std::string(name)) + "' (expected t, PI, sin, cos)");
    }
  }

  void expect_close(int open_column) {
    if (tok_.kind != Kind::kRParen) {
      throw ExpressionError(tok_column(), "expected ')' to close '('", open_column);
    }
    advance();
  }

  // ---- emitting ----

  void emit(std::uint8_t op, double k, int col) {
    code_.push_back({op, k});
    cols_.push_back(col);
  }
  void pop() {
    code_.pop_back();
    cols_.pop_back();
  }
  bool is_leaf(std::size_t i) const { return code_[i].op == kConst || code_[i].op == kT; }

  // The right operand's code starts at `right`; the left operand's root is
  // the instruction just before it (in postfix a subtree ends at its root,
  // and a root that is a leaf is the whole subtree).
  void emit_binary(Binary b, std::size_t right, int col) {
    const std::size_t left_root = right - 1;
    const bool left_leaf = is_leaf(left_root);
    const bool right_leaf = is_leaf(code_.size() - 1);
    const Expression::Instr l = code_[left_root];
    const Expression::Instr r = code_.back();
    const int left_col = cols_[left_root];
    if (left_leaf && right_leaf) {
      pop();
      pop();
      if (l.op == kConst && r.op == kConst) {
        const double v = apply(b, l.k, r.k);
        // Non-finite results stay unfolded so that every constant in the
        // program can be printed back as a number.
        if (std::isfinite(v)) return emit(kConst, v, left_col);
        emit(kConst, l.k, left_col);
        return emit(binary_op(b, kSK), r.k, col);
      }
      if (l.op == kConst) return emit(binary_op(b, kKT), l.k, left_col);
      if (r.op == kConst) return emit(binary_op(b, kTK), r.k, left_col);
      return emit(binary_op(b, kTT), 0.0, left_col);
    }
    if (left_leaf) {
      // The right operand's code does not look below its own values, so the
      // left leaf can move into the operator.
      code_.erase(code_.begin() + static_cast<std::ptrdiff_t>(left_root));
      cols_.erase(cols_.begin() + static_cast<std::ptrdiff_t>(left_root));
      return emit(binary_op(b, l.op == kConst ? kKS : kTS), l.k, col);
    }
    if (right_leaf) {
      pop();
      return emit(binary_op(b, r.op == kConst ? kSK : kST), r.k, col);
    }
    emit(binary_op(b, kPS), 0.0, col);
  }

  void emit_unary(Op op, int col) {
    Expression::Instr& top = code_.back();
    if (top.op == kConst) {
      const double v = apply_unary(op, top.k);
      if (std::isfinite(v)) {
        top.k = v;
        return;
      }
    }
    emit(op, 0.0, col);
  }

  // The most values the program keeps at once; throws past the capacity.
  int check_depth(const std::vector<Expression::Instr>& code) const {
    int depth = 0;
    int max_depth = 0;
    for (std::size_t i = 0; i < code.size(); ++i) {
      depth += stack_effect(code[i].op);
      if (depth > Expression::kMaxStackDepth) {
        throw ExpressionError(cols_[i], "expression too deep: needs more than " +
                                            std::to_string(Expression::kMaxStackDepth) +
                                            " values on the evaluation stack");
      }
      if (depth > max_depth) max_depth = depth;
    }
    return max_depth;
  }

  std::string_view text_;
  Token tok_;
  int nesting_ = 0;
  std::vector<Expression::Instr> code_;
  std::vector<int> cols_;  // column of each instruction, for errors
};

Expression Expression::compile(std::string_view text) { return ExpressionCompiler(text).run(); }

}  // namespace animrt

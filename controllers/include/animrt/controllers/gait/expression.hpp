#pragma once
// The curve expression language of gait files and of evolved phenotypes:
//
//   expr   := term (('+' | '-') term)*          left associative
//   term   := unary (('*' | '/') unary)*        left associative
//   unary  := '-' unary | primary               binds tighter than * and /
//   primary:= number | 't' | 'PI' | ('sin' | 'cos') '(' expr ')' | '(' expr ')'
//
// Numbers are decimal (2, 6.97, .5, 1e-3, 2.5E+4); a leading '-' is unary
// minus. Division is protected: a / b is 1 when b == 0 (the usual GP rule),
// so evolved curves never divide by zero.
//
// An Expression is compiled once into a flat stack program and evaluated many
// times. Only fully constant subtrees are folded, and every operation runs in
// the order of the parse tree, so eval() is bit-identical to evaluating that
// tree node by node.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace animrt {

// A syntax or compile error. column() is 1-based within the expression text
// (one past the last character for errors at the end).
class ExpressionError : public std::runtime_error {
 public:
  // `related_column` (0 = none) is a second position the message refers to,
  // e.g. the '(' that a missing ')' should close.
  ExpressionError(int column, std::string detail, int related_column = 0);

  int column() const { return column_; }
  int related_column() const { return related_column_; }
  // The message without any position, e.g. "expected ')' to close '('".
  const std::string& detail() const { return detail_; }
  // detail() plus " at column N" when there is a related column. Callers
  // that embed the expression in a file can rebuild it from detail() and
  // their own column of related_column().
  std::string message() const;
  // what() is "column C: " + message().

 private:
  int column_;
  int related_column_;
  std::string detail_;
};

class Expression {
 public:
  // Most values one evaluation keeps at once; deeper programs are rejected
  // when compiled, so eval() can use a fixed array on the stack.
  static constexpr int kMaxStackDepth = 64;
  // Most nested parentheses, function calls and unary minuses accepted (it
  // bounds the parser's recursion).
  static constexpr int kMaxNesting = 256;

  // The constant 0.
  Expression();

  // Parses and compiles. Throws ExpressionError.
  static Expression compile(std::string_view text);

  // The value at `t`. Never allocates, never throws.
  double eval(double t) const noexcept;

  // The program as an expression (folded constants printed exactly) that
  // compiles back to a bit-identical program.
  std::string to_string() const;

  // Instructions in the compiled program and the stack depth it needs.
  std::size_t size() const { return code_.size(); }
  int stack_depth() const { return depth_; }

 private:
  friend class ExpressionCompiler;

  // One instruction; the opcodes are private to the implementation
  // (controllers/gait/expression_program.hpp).
  struct Instr {
    std::uint8_t op;
    double k;  // immediate operand, when the opcode has one
  };

  Expression(std::vector<Instr> code, int depth) : code_(std::move(code)), depth_(depth) {}

  std::vector<Instr> code_;
  int depth_ = 1;
};

}  // namespace animrt

// Expression: a small arithmetic language for spatially varying scene values
// (parameter maps, initial states, fixed regions), compiled once and evaluated
// per cell. Numbers, named variables, + - * / ^ (right-associative power),
// unary - and !, comparisons (< <= > >= == !=, giving 1 or 0), && ||, the
// conditional c ? a : b, parentheses and the functions listed by
// expressionFunctions(). Example, seed 004 Table 1 note a:
//   Expression e("r < 0.25 ? 16 - 0.5*r/0.25 : 16", {"x", "y", "r"});
//   double beta = e.evaluate({0.5, 0.5, 0.0});
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace morphoflow {

// The longest expression, and its deepest nesting, that compile.
constexpr size_t kMaxExpressionLength = 10000;
constexpr int kMaxExpressionDepth = 200;

// A syntax error; `column` is the 0-based offset into the expression text.
class ExpressionError : public std::runtime_error {
 public:
  ExpressionError(size_t column, const std::string& message) : std::runtime_error(message), column_(column) {}
  size_t column() const { return column_; }

 private:
  size_t column_;
};

class Expression {
 public:
  // Compiles `text`; the variables are bound by position at evaluation. Throws ExpressionError.
  Expression(const std::string& text, std::vector<std::string> variables);
  Expression(const Expression&);
  Expression& operator=(const Expression&);
  Expression(Expression&&) noexcept;
  Expression& operator=(Expression&&) noexcept;
  ~Expression();

  // `values` holds one value per variable, in the order given at construction.
  double evaluate(const double* values) const;
  double evaluate(const std::vector<double>& values) const { return evaluate(values.data()); }
  const std::string& text() const { return text_; }
  // The derivative along variable number `variable` at `values`: analytic
  // (forward mode, the chain rule through every operator and function)
  // where the expression is differentiable there, else the centred
  // difference over a relative step of 1e-6; *analytic says which.
  double derivative(const double* values, size_t variable, bool* analytic = nullptr) const;
  // True when no variable occurs (the expression is a constant).
  bool constant() const;

  struct Node;

 private:
  std::string text_;
  std::vector<std::string> variables_;
  std::unique_ptr<Node> root_;
};

// "name(arity)" for every function the language knows, for error messages and docs.
std::vector<std::string> expressionFunctions();

}  // namespace morphoflow

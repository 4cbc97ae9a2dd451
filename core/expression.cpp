// Recursive-descent compiler for Expression into a small tree, evaluated recursively.
#include "core/expression.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace morphoflow {

namespace {

// d: the derivative of the call from its arguments a and their derivatives
// da; clears *smooth where the function has none there (a kink or a jump).
struct Function {
  const char* name;
  int arity;
  double (*f)(const double*);
  double (*d)(const double* a, const double* da, bool* smooth);
};

// A jump of a piecewise-constant function at a, crossed when da != 0.
double flat(bool atJump, double da, bool* smooth) {
  if (atJump && da != 0.0) *smooth = false;
  return 0.0;
}
// d/dx x^y, for y's derivative dy too (x > 0; else y must not vary).
double powDerivative(double x, double y, double dx, double dy, bool* smooth) {
  if (x > 0.0) return std::pow(x, y) * (dy * std::log(x) + y * dx / x);
  if (dy != 0.0 || (x == 0.0 && y < 1.0 && dx != 0.0)) *smooth = false;
  return y * std::pow(x, y - 1.0) * dx;
}
double smoothstepDerivative(const double* a, const double* da, bool* smooth) {
  if (!(a[1] > a[0])) return flat(a[2] == a[0], da[2], smooth);
  const double w = a[1] - a[0], t = (a[2] - a[0]) / w;
  if (t <= 0.0 || t >= 1.0) return flat(t == 0.0 || t == 1.0, da[2] - da[0], smooth);
  const double dt = ((da[2] - da[0]) * w - (a[2] - a[0]) * (da[1] - da[0])) / (w * w);
  return 6.0 * t * (1.0 - t) * dt;
}

double clamp3(const double* a) { return std::min(std::max(a[0], a[1]), a[2]); }
double smoothstep3(const double* a) {
  if (!(a[1] > a[0])) return a[2] < a[0] ? 0.0 : 1.0;
  double t = std::clamp((a[2] - a[0]) / (a[1] - a[0]), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

const std::vector<Function>& functions() {
  static const std::vector<Function> f = {
      {"sin", 1, [](const double* a) { return std::sin(a[0]); },
       [](const double* a, const double* d, bool*) { return std::cos(a[0]) * d[0]; }},
      {"cos", 1, [](const double* a) { return std::cos(a[0]); },
       [](const double* a, const double* d, bool*) { return -std::sin(a[0]) * d[0]; }},
      {"tan", 1, [](const double* a) { return std::tan(a[0]); },
       [](const double* a, const double* d, bool*) { return d[0] / (std::cos(a[0]) * std::cos(a[0])); }},
      {"asin", 1, [](const double* a) { return std::asin(a[0]); },
       [](const double* a, const double* d, bool* s) {
         if (!(std::abs(a[0]) < 1.0)) *s = false;
         return d[0] / std::sqrt(1.0 - a[0] * a[0]);
       }},
      {"acos", 1, [](const double* a) { return std::acos(a[0]); },
       [](const double* a, const double* d, bool* s) {
         if (!(std::abs(a[0]) < 1.0)) *s = false;
         return -d[0] / std::sqrt(1.0 - a[0] * a[0]);
       }},
      {"atan", 1, [](const double* a) { return std::atan(a[0]); },
       [](const double* a, const double* d, bool*) { return d[0] / (1.0 + a[0] * a[0]); }},
      {"atan2", 2, [](const double* a) { return std::atan2(a[0], a[1]); },
       [](const double* a, const double* d, bool* s) {
         const double r2 = a[0] * a[0] + a[1] * a[1];
         if (!(r2 > 0.0)) *s = false;
         return (a[1] * d[0] - a[0] * d[1]) / r2;
       }},
      {"exp", 1, [](const double* a) { return std::exp(a[0]); },
       [](const double* a, const double* d, bool*) { return std::exp(a[0]) * d[0]; }},
      {"log", 1, [](const double* a) { return std::log(a[0]); },
       [](const double* a, const double* d, bool* s) {
         if (!(a[0] > 0.0)) *s = false;
         return d[0] / a[0];
       }},
      {"sqrt", 1, [](const double* a) { return std::sqrt(a[0]); },
       [](const double* a, const double* d, bool* s) {
         if (!(a[0] > 0.0)) *s = false;
         return d[0] / (2.0 * std::sqrt(a[0]));
       }},
      {"abs", 1, [](const double* a) { return std::abs(a[0]); },
       [](const double* a, const double* d, bool* s) {
         if (a[0] == 0.0 && d[0] != 0.0) *s = false;
         return a[0] < 0.0 ? -d[0] : d[0];
       }},
      {"floor", 1, [](const double* a) { return std::floor(a[0]); },
       [](const double* a, const double* d, bool* s) { return flat(std::floor(a[0]) == a[0], d[0], s); }},
      {"ceil", 1, [](const double* a) { return std::ceil(a[0]); },
       [](const double* a, const double* d, bool* s) { return flat(std::ceil(a[0]) == a[0], d[0], s); }},
      {"round", 1, [](const double* a) { return std::round(a[0]); },
       [](const double* a, const double* d, bool* s) {
         return flat(std::abs(a[0] - std::trunc(a[0])) == 0.5, d[0], s);
       }},
      {"min", 2, [](const double* a) { return std::min(a[0], a[1]); },
       [](const double* a, const double* d, bool* s) {
         if (a[0] == a[1] && d[0] != d[1]) *s = false;
         return a[0] <= a[1] ? d[0] : d[1];
       }},
      {"max", 2, [](const double* a) { return std::max(a[0], a[1]); },
       [](const double* a, const double* d, bool* s) {
         if (a[0] == a[1] && d[0] != d[1]) *s = false;
         return a[0] >= a[1] ? d[0] : d[1];
       }},
      {"pow", 2, [](const double* a) { return std::pow(a[0], a[1]); },
       [](const double* a, const double* d, bool* s) { return powDerivative(a[0], a[1], d[0], d[1], s); }},
      {"mod", 2, [](const double* a) { return a[0] - a[1] * std::floor(a[0] / a[1]); },
       [](const double* a, const double* d, bool* s) {
         const double q = a[0] / a[1];
         if (std::floor(q) == q && (d[0] != 0.0 || d[1] != 0.0)) *s = false;
         return d[0] - d[1] * std::floor(q);
       }},
      {"step", 2, [](const double* a) { return a[1] < a[0] ? 0.0 : 1.0; },
       [](const double* a, const double* d, bool* s) { return flat(a[1] == a[0], d[1] - d[0], s); }},
      {"clamp", 3, clamp3,
       [](const double* a, const double* d, bool* s) {
         if ((a[0] == a[1] && d[0] != d[1]) || (a[0] == a[2] && d[0] != d[2])) *s = false;
         return a[0] < a[1] ? d[1] : a[0] > a[2] ? d[2] : d[0];
       }},
      {"lerp", 3, [](const double* a) { return a[0] + (a[1] - a[0]) * a[2]; },
       [](const double* a, const double* d, bool*) { return d[0] + (d[1] - d[0]) * a[2] + (a[1] - a[0]) * d[2]; }},
      {"smoothstep", 3, smoothstep3, smoothstepDerivative},
  };
  return f;
}

enum class Kind { Number, Variable, Negate, Not, Binary, Conditional, Call };
enum class Op { Add, Sub, Mul, Div, Pow, Lt, Le, Gt, Ge, Eq, Ne, And, Or };

}  // namespace

struct Expression::Node {
  Kind kind = Kind::Number;
  Op op = Op::Add;
  double value = 0.0;
  size_t index = 0;
  const Function* function = nullptr;
  std::vector<std::unique_ptr<Node>> args;

  std::unique_ptr<Node> clone() const {
    auto n = std::make_unique<Node>();
    n->kind = kind;
    n->op = op;
    n->value = value;
    n->index = index;
    n->function = function;
    for (const auto& a : args) n->args.push_back(a->clone());
    return n;
  }
  bool usesVariables() const {
    if (kind == Kind::Variable) return true;
    return std::any_of(args.begin(), args.end(), [](const auto& a) { return a->usesVariables(); });
  }
  double eval(const double* v) const {
    switch (kind) {
      case Kind::Number: return value;
      case Kind::Variable: return v[index];
      case Kind::Negate: return -args[0]->eval(v);
      case Kind::Not: return args[0]->eval(v) != 0.0 ? 0.0 : 1.0;
      case Kind::Conditional: return args[0]->eval(v) != 0.0 ? args[1]->eval(v) : args[2]->eval(v);
      case Kind::Call: {
        double a[3];
        for (size_t i = 0; i < args.size(); ++i) a[i] = args[i]->eval(v);
        return function->f(a);
      }
      case Kind::Binary: break;
    }
    if (op == Op::And) return args[0]->eval(v) != 0.0 && args[1]->eval(v) != 0.0 ? 1.0 : 0.0;
    if (op == Op::Or) return args[0]->eval(v) != 0.0 || args[1]->eval(v) != 0.0 ? 1.0 : 0.0;
    const double a = args[0]->eval(v), b = args[1]->eval(v);
    switch (op) {
      case Op::Add: return a + b;
      case Op::Sub: return a - b;
      case Op::Mul: return a * b;
      case Op::Div: return a / b;
      case Op::Pow: return std::pow(a, b);
      case Op::Lt: return a < b;
      case Op::Le: return a <= b;
      case Op::Gt: return a > b;
      case Op::Ge: return a >= b;
      case Op::Eq: return a == b;
      case Op::Ne: return a != b;
      default: return 0.0;
    }
  }
  // Forward-mode differentiation along variable `var`: the value's derivative
  // by the chain rule; *smooth cleared where a kink or jump is crossed.
  double derive(const double* v, size_t var, bool* smooth) const {
    switch (kind) {
      case Kind::Number:
        return 0.0;
      case Kind::Variable:
        return index == var ? 1.0 : 0.0;
      case Kind::Negate:
        return -args[0]->derive(v, var, smooth);
      case Kind::Not:
        return 0.0;
      case Kind::Conditional:
        return args[0]->eval(v) != 0.0 ? args[1]->derive(v, var, smooth) : args[2]->derive(v, var, smooth);
      case Kind::Call: {
        double a[3], d[3];
        for (size_t i = 0; i < args.size(); ++i) a[i] = args[i]->eval(v), d[i] = args[i]->derive(v, var, smooth);
        return function->d(a, d, smooth);
      }
      case Kind::Binary:
        break;
    }
    if (op != Op::Add && op != Op::Sub && op != Op::Mul && op != Op::Div && op != Op::Pow) return 0.0;
    const double a = args[0]->eval(v), b = args[1]->eval(v);
    const double da = args[0]->derive(v, var, smooth), db = args[1]->derive(v, var, smooth);
    switch (op) {
      case Op::Add:
        return da + db;
      case Op::Sub:
        return da - db;
      case Op::Mul:
        return da * b + a * db;
      case Op::Div:
        return (da * b - a * db) / (b * b);
      default:
        return powDerivative(a, b, da, db, smooth);
    }
  }
};

namespace {

using NodePtr = std::unique_ptr<Expression::Node>;

class Parser {
 public:
  Parser(const std::string& text, const std::vector<std::string>& vars) : s_(text), vars_(vars) {}

  NodePtr parse() {
    NodePtr n = conditional();
    skip();
    if (p_ < s_.size()) fail(p_, std::string("unexpected '") + s_[p_] + "'");
    return n;
  }

 private:
  [[noreturn]] void fail(size_t at, const std::string& msg) const { throw ExpressionError(at, msg); }
  void skip() {
    while (p_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[p_]))) ++p_;
  }
  bool accept(const char* tok) {
    skip();
    size_t n = std::char_traits<char>::length(tok);
    if (s_.compare(p_, n, tok) != 0) return false;
    // "<" must not swallow the start of "<=", nor "=" / "!" of "==" / "!=".
    if (n == 1 && p_ + 1 < s_.size() && s_[p_ + 1] == '=' && (tok[0] == '<' || tok[0] == '>' || tok[0] == '!'))
      return false;
    p_ += n;
    return true;
  }
  void expect(const char* tok, const char* what) {
    if (!accept(tok)) {
      skip();
      fail(p_, std::string("expected ") + what +
                   (p_ < s_.size() ? std::string(", found '") + s_[p_] + "'" : ", found the end"));
    }
  }
  static NodePtr make(Kind k, std::vector<NodePtr> args, Op op = Op::Add) {
    auto n = std::make_unique<Expression::Node>();
    n->kind = k;
    n->op = op;
    n->args = std::move(args);
    return n;
  }
  static NodePtr binary(Op op, NodePtr a, NodePtr b) {
    std::vector<NodePtr> v;
    v.push_back(std::move(a));
    v.push_back(std::move(b));
    return make(Kind::Binary, std::move(v), op);
  }

  // Nesting (parentheses, unary signs, chained conditionals) is bounded, so
  // thousands of '(' are an error, not a stack overflow.
  struct Deeper {
    explicit Deeper(Parser* p) : p_(p) {
      if (++p_->depth_ > kMaxExpressionDepth)
        p_->fail(p_->p_, "nested more than " + std::to_string(kMaxExpressionDepth) + " deep");
    }
    ~Deeper() { --p_->depth_; }
    Parser* p_;
  };

  NodePtr conditional() {
    Deeper deeper(this);
    NodePtr c = logicalOr();
    if (!accept("?")) return c;
    NodePtr a = conditional();
    expect(":", "':' of the conditional c ? a : b");
    NodePtr b = conditional();
    std::vector<NodePtr> v;
    v.push_back(std::move(c));
    v.push_back(std::move(a));
    v.push_back(std::move(b));
    return make(Kind::Conditional, std::move(v));
  }
  NodePtr logicalOr() {
    NodePtr n = logicalAnd();
    while (accept("||")) n = binary(Op::Or, std::move(n), logicalAnd());
    return n;
  }
  NodePtr logicalAnd() {
    NodePtr n = comparison();
    while (accept("&&")) n = binary(Op::And, std::move(n), comparison());
    return n;
  }
  NodePtr comparison() {
    NodePtr n = additive();
    for (;;) {
      Op op;
      if (accept("<=")) op = Op::Le;
      else if (accept(">=")) op = Op::Ge;
      else if (accept("==")) op = Op::Eq;
      else if (accept("!=")) op = Op::Ne;
      else if (accept("<")) op = Op::Lt;
      else if (accept(">")) op = Op::Gt;
      else return n;
      n = binary(op, std::move(n), additive());
    }
  }
  NodePtr additive() {
    NodePtr n = multiplicative();
    for (;;) {
      if (accept("+")) n = binary(Op::Add, std::move(n), multiplicative());
      else if (accept("-")) n = binary(Op::Sub, std::move(n), multiplicative());
      else return n;
    }
  }
  NodePtr multiplicative() {
    NodePtr n = unary();
    for (;;) {
      if (accept("*")) n = binary(Op::Mul, std::move(n), unary());
      else if (accept("/")) n = binary(Op::Div, std::move(n), unary());
      else return n;
    }
  }
  NodePtr unary() {
    Deeper deeper(this);
    if (accept("-")) {
      std::vector<NodePtr> v;
      v.push_back(unary());
      return make(Kind::Negate, std::move(v));
    }
    if (accept("+")) return unary();
    if (accept("!")) {
      std::vector<NodePtr> v;
      v.push_back(unary());
      return make(Kind::Not, std::move(v));
    }
    return power();
  }
  NodePtr power() {
    NodePtr base = primary();
    if (accept("^")) return binary(Op::Pow, std::move(base), unary());  // right-associative, -2^2 = -(2^2)
    return base;
  }
  NodePtr primary() {
    skip();
    if (p_ >= s_.size()) fail(p_, "expected a number, a name or '(', found the end");
    const char c = s_[p_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      const char* begin = s_.c_str() + p_;
      char* end = nullptr;
      double v = std::strtod(begin, &end);
      if (end == begin) fail(p_, "malformed number");
      p_ += size_t(end - begin);
      auto n = make(Kind::Number, {});
      n->value = v;
      return n;
    }
    if (accept("(")) {
      NodePtr n = conditional();
      expect(")", "')'");
      return n;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const size_t start = p_;
      while (p_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[p_])) || s_[p_] == '_')) ++p_;
      const std::string name = s_.substr(start, p_ - start);
      skip();
      if (p_ < s_.size() && s_[p_] == '(') return call(name, start);
      for (size_t i = 0; i < vars_.size(); ++i)
        if (vars_[i] == name) {
          auto n = make(Kind::Variable, {});
          n->index = i;
          return n;
        }
      if (name == "pi") {
        auto n = make(Kind::Number, {});
        n->value = M_PI;
        return n;
      }
      std::string known;
      for (const std::string& v : vars_) known += (known.empty() ? "" : ", ") + v;
      fail(start, "unknown name '" + name + "' (variables: " + known + ", pi)");
    }
    fail(p_, std::string("unexpected '") + c + "'");
  }
  NodePtr call(const std::string& name, size_t at) {
    const Function* f = nullptr;
    for (const Function& g : functions())
      if (name == g.name) f = &g;
    if (!f) {
      std::string known;
      for (const std::string& g : expressionFunctions()) known += (known.empty() ? "" : ", ") + g;
      fail(at, "unknown function '" + name + "' (functions: " + known + ")");
    }
    expect("(", "'('");
    std::vector<NodePtr> args;
    if (!accept(")")) {
      do args.push_back(conditional());
      while (accept(","));
      expect(")", "')' or ','");
    }
    if (int(args.size()) != f->arity)
      fail(at, name + " takes " + std::to_string(f->arity) + " argument" + (f->arity > 1 ? "s" : "") + ", found " +
                   std::to_string(args.size()));
    auto n = make(Kind::Call, std::move(args));
    n->function = f;
    return n;
  }

  const std::string& s_;
  const std::vector<std::string>& vars_;
  size_t p_ = 0;
  int depth_ = 0;
};

}  // namespace

Expression::Expression(const std::string& text, std::vector<std::string> variables)
    : text_(text), variables_(std::move(variables)) {
  if (text_.size() > kMaxExpressionLength)
    throw ExpressionError(kMaxExpressionLength, "longer than " + std::to_string(kMaxExpressionLength) + " characters");
  root_ = Parser(text_, variables_).parse();
}
Expression::Expression(const Expression& o) : text_(o.text_), variables_(o.variables_), root_(o.root_->clone()) {}
Expression& Expression::operator=(const Expression& o) {
  if (this != &o) {
    text_ = o.text_;
    variables_ = o.variables_;
    root_ = o.root_->clone();
  }
  return *this;
}
Expression::Expression(Expression&&) noexcept = default;
Expression& Expression::operator=(Expression&&) noexcept = default;
Expression::~Expression() = default;

double Expression::evaluate(const double* values) const { return root_->eval(values); }
bool Expression::constant() const { return !root_->usesVariables(); }

double Expression::derivative(const double* values, size_t variable, bool* analytic) const {
  bool smooth = true;
  const double d = root_->derive(values, variable, &smooth);
  if (analytic) *analytic = smooth && std::isfinite(d);
  if (smooth && std::isfinite(d)) return d;
  // Not differentiable here: the centred difference over a step of 1e-6 (relative).
  std::vector<double> x(values, values + variables_.size());
  const double at = x[variable], step = 1e-6 * std::max(1.0, std::abs(at));
  x[variable] = at + step;
  const double hi = root_->eval(x.data());
  x[variable] = at - step;
  return (hi - root_->eval(x.data())) / (2.0 * step);
}

std::vector<std::string> expressionFunctions() {
  std::vector<std::string> names;
  for (const Function& f : functions()) names.push_back(std::string(f.name) + "(" + std::to_string(f.arity) + ")");
  return names;
}

}  // namespace morphoflow

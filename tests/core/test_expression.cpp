// The expression language of scene fields: precedence and associativity as in
// C (with ^ for a right-associative power), functions, conditionals, errors
// that point at the offending column; spatial fields at cell centres.
#include <gtest/gtest.h>

#include <cmath>

#include "core/expression.h"
#include "core/spatial_field.h"

using namespace morphoflow;

namespace {
double eval(const std::string& text, std::vector<double> values = {}, std::vector<std::string> vars = {}) {
  return Expression(text, std::move(vars)).evaluate(values);
}
size_t errorColumn(const std::string& text) {
  try {
    Expression(text, {"x"});
  } catch (const ExpressionError& e) {
    return e.column();
  }
  ADD_FAILURE() << "no error for " << text;
  return size_t(-1);
}
}  // namespace

TEST(Expression, PrecedenceAndAssociativity) {
  EXPECT_DOUBLE_EQ(eval("1 + 2 * 3"), 7.0);
  EXPECT_DOUBLE_EQ(eval("(1 + 2) * 3"), 9.0);
  EXPECT_DOUBLE_EQ(eval("8 / 4 / 2"), 1.0);      // left-associative
  EXPECT_DOUBLE_EQ(eval("10 - 4 - 3"), 3.0);
  EXPECT_DOUBLE_EQ(eval("2 ^ 3 ^ 2"), 512.0);    // right-associative
  EXPECT_DOUBLE_EQ(eval("-2 ^ 2"), -4.0);        // power binds tighter than unary minus
  EXPECT_DOUBLE_EQ(eval("2 ^ -1"), 0.5);
  EXPECT_DOUBLE_EQ(eval("1.5e2 + .5"), 150.5);
  EXPECT_DOUBLE_EQ(eval("pi"), M_PI);
}

TEST(Expression, ComparisonsLogicAndConditionals) {
  EXPECT_EQ(eval("1 < 2"), 1.0);
  EXPECT_EQ(eval("2 <= 2 && 3 >= 4"), 0.0);
  EXPECT_EQ(eval("2 == 2 || 1 / 0 > 0"), 1.0);
  EXPECT_EQ(eval("!(1 != 1)"), 1.0);
  // Nested conditionals associate to the right, like C.
  const char* piecewise = "x < 0.25 ? 1 : x < 0.5 ? 2 : 3";
  EXPECT_EQ(eval(piecewise, {0.1}, {"x"}), 1.0);
  EXPECT_EQ(eval(piecewise, {0.3}, {"x"}), 2.0);
  EXPECT_EQ(eval(piecewise, {0.9}, {"x"}), 3.0);
}

TEST(Expression, FunctionsMatchTheStandardLibrary) {
  EXPECT_DOUBLE_EQ(eval("sin(x)^2 + cos(x)^2", {0.7}, {"x"}), std::pow(std::sin(0.7), 2) + std::pow(std::cos(0.7), 2));
  EXPECT_DOUBLE_EQ(eval("atan2(1, -1)"), std::atan2(1.0, -1.0));
  EXPECT_DOUBLE_EQ(eval("lerp(15.85, 16.35, 0.5)"), 16.1);
  EXPECT_DOUBLE_EQ(eval("clamp(5, 0, 1)"), 1.0);
  EXPECT_DOUBLE_EQ(eval("mod(-1, 3)"), 2.0);
  EXPECT_DOUBLE_EQ(eval("smoothstep(0, 1, 0.5)"), 0.5);
  EXPECT_DOUBLE_EQ(eval("max(min(3, 2), 1) + abs(-4) + sqrt(9) + exp(0) + log(1)"), 10.0);
  EXPECT_TRUE(Expression("2 * pi", {}).constant());
  EXPECT_FALSE(Expression("2 * x", {"x"}).constant());
}

TEST(Expression, ErrorsPointAtTheColumn) {
  EXPECT_EQ(errorColumn("1 + foo"), 4u);           // unknown name
  EXPECT_EQ(errorColumn("sinh(x)"), 0u);           // unknown function
  EXPECT_EQ(errorColumn("lerp(1, 2)"), 0u);        // wrong arity
  EXPECT_EQ(errorColumn("(1 + 2"), 6u);            // missing ')'
  EXPECT_EQ(errorColumn("1 + * 2"), 4u);
  EXPECT_EQ(errorColumn("x ? 1"), 5u);             // missing ':'
  EXPECT_EQ(errorColumn("1 2"), 2u);               // trailing input
  EXPECT_EQ(errorColumn(""), 0u);
}

TEST(Expression, CopiesEvaluateIndependently) {
  Expression a("x * 2", {"x"});
  Expression b = a;
  a = Expression("x + 1", {"x"});
  EXPECT_EQ(b.evaluate({3.0}), 6.0);
  EXPECT_EQ(a.evaluate({3.0}), 4.0);
}

TEST(SpatialField, LinearGradientAtCellCentres) {
  SpatialField f;
  f.expression = "lerp(15.85, 16.35, y)";  // seed 004 fig. 4
  const IVec<2> n(4, 8);
  std::vector<double> v = sampleSpatialField<2>(f, n);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(v[size_t(j * 4 + i)], 15.85 + 0.5 * (j + 0.5) / 8, 1e-12);
}

TEST(SpatialField, RadiusAngleAndIndices) {
  SpatialField f;
  const IVec<2> n(16, 16);
  f.expression = "r";
  std::vector<double> r = sampleSpatialField<2>(f, n);
  f.expression = "theta";
  std::vector<double> th = sampleSpatialField<2>(f, n);
  f.expression = "i + 100 * j + 1e4 * (nx + ny + nz + k)";
  std::vector<double> idx = sampleSpatialField<2>(f, n);
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      size_t c = size_t(j * 16 + i);
      double x = (i + 0.5) / 16 - 0.5, y = (j + 0.5) / 16 - 0.5;
      EXPECT_NEAR(r[c], std::hypot(x, y), 1e-12);
      EXPECT_NEAR(th[c], std::atan2(y, x), 1e-12);
      EXPECT_EQ(idx[c], i + 100 * j + 1e4 * 33);
    }
  // 3D: z and k vary along the third axis.
  f.expression = "z + 10 * k";
  std::vector<double> z = sampleSpatialField<3>(f, IVec<3>(2, 2, 4));
  EXPECT_NEAR(z[3 * 4], (3 + 0.5) / 4 + 30, 1e-12);
}

TEST(SpatialField, ImageIsBilinearYUpAndMappedToTheRange) {
  // A 2x1 image, left pixel 0 and right pixel 1, mapped to [10, 20]: on a grid
  // of 4 columns the centres u = 1/8, 3/8, 5/8, 7/8 sit at pixel positions
  // -0.25, 0.25, 0.75, 1.25 (clamped at the ends).
  SpatialField f;
  f.imageWidth = 2;
  f.imageHeight = 1;
  f.image = {0.0f, 1.0f};
  f.range[0] = 10;
  f.range[1] = 20;
  std::vector<double> v = sampleSpatialField<2>(f, IVec<2>(4, 3));
  const double expect[4] = {10, 12.5, 17.5, 20};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(v[size_t(j * 4 + i)], expect[i], 1e-6);
  // Top image row is the domain's top (y up).
  f.imageWidth = 1;
  f.imageHeight = 2;
  f.image = {1.0f, 0.0f};  // top white, bottom black
  std::vector<double> w = sampleSpatialField<2>(f, IVec<2>(1, 2));
  EXPECT_LT(w[0], w[1]);
}

TEST(Expression, DerivativesAreAnalyticWhereTheExpressionIsSmooth) {
  const double t = 0.7;
  bool analytic = false;
  Expression a("0.5 + 0.2 * sin(3 * t) + t^2 / (1 + t)", {"t"});
  const double exact = 0.6 * std::cos(3 * t) + (2 * t * (1 + t) - t * t) / ((1 + t) * (1 + t));
  EXPECT_NEAR(a.derivative(&t, 0, &analytic), exact, 1e-14);
  EXPECT_TRUE(analytic);
  Expression b("t < 1 ? smoothstep(0, 2, t) : exp(-t)", {"t"});
  EXPECT_NEAR(b.derivative(&t, 0, &analytic), 6 * 0.35 * 0.65 / 2, 1e-14);
  EXPECT_TRUE(analytic);
  Expression c("atan2(sqrt(t), 1 - t) + mod(t, 0.3) + pow(t, t) + clamp(t, 0, 2) + lerp(1, t, t)", {"t"});
  const double h = 1e-6;
  double lo = t - h, hi = t + h;
  EXPECT_NEAR(c.derivative(&t, 0, &analytic), (c.evaluate(&hi) - c.evaluate(&lo)) / (2 * h), 1e-7);
  EXPECT_TRUE(analytic);
}

TEST(Expression, AtAKinkTheDerivativeIsACentredDifference) {
  bool analytic = true;
  const double zero = 0.0, one = 1.0;
  Expression kink("abs(t)", {"t"});
  EXPECT_NEAR(kink.derivative(&zero, 0, &analytic), 0.0, 1e-12);  // the mean of the sides
  EXPECT_FALSE(analytic);
  Expression jump("floor(t)", {"t"});
  EXPECT_GT(jump.derivative(&one, 0, &analytic), 1e4);  // a jump is a huge rate, as a teleport is
  EXPECT_FALSE(analytic);
  const double half = 0.5;
  EXPECT_EQ(jump.derivative(&half, 0, &analytic), 0.0);  // flat between the jumps
  EXPECT_TRUE(analytic);
}

#include "slam/eval/chi_square.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "slam/types/check.h"

namespace slamrig::slam {
namespace {

// The standard normal quantile (Acklam's rational approximation, relative error < 1.2e-9).
double NormalQuantile(double p) {
  static constexpr double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                 -2.759285104469687e+02, 1.383577518672690e+02,
                                 -3.066479806614716e+01, 2.506628277459239e+00};
  static constexpr double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                 -1.556989798598866e+02, 6.680131188771972e+01,
                                 -1.328068155288572e+01};
  static constexpr double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                 -2.400758277161838e+00, -2.549732539343734e+00,
                                 4.374664141464968e+00,  2.938163982698783e+00};
  static constexpr double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                                 2.445134137142996e+00, 3.754408661907416e+00};
  const double low = 0.02425;
  if (p < low) {
    const double q = std::sqrt(-2.0 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  }
  if (p > 1.0 - low) return -NormalQuantile(1.0 - p);
  const double q = p - 0.5;
  const double r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

// The regularised lower incomplete gamma P(a, x) by its power series (Abramowitz and Stegun,
// Eq. 6.5.29), which converges for every x > 0.
double LowerGammaRatio(double a, double x) {
  if (x <= 0.0) return 0.0;
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 10000 && term > sum * 1e-16; ++n) {
    term *= x / (a + n);
    sum += term;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

}  // namespace

double ChiSquareQuantile(double p, double dof) {
  SLAMRIG_CHECK(p > 0.0 && p < 1.0 && dof > 0.0, "ChiSquareQuantile: p in (0, 1), dof > 0");
  // The Wilson-Hilferty start, then Newton steps on the distribution function.
  const double h = 2.0 / (9.0 * dof);
  const double t = 1.0 - h + NormalQuantile(p) * std::sqrt(h);
  const double a = 0.5 * dof;
  double x = std::max(dof * t * t * t, 1e-3);
  for (int i = 0; i < 50; ++i) {
    const double density = std::exp((a - 1.0) * std::log(0.5 * x) - 0.5 * x - std::lgamma(a)) * 0.5;
    const double step = (LowerGammaRatio(a, 0.5 * x) - p) / density;
    x = std::max(x - step, 0.5 * x);
    if (std::abs(step) < 1e-12 * x) break;
  }
  return x;
}

double FQuantile(double p, double d1, double d2) {
  SLAMRIG_CHECK(p >= 0.5 && p < 1.0 && d1 > 0.0 && d2 > 0.0, "FQuantile: p in [0.5, 1), dof > 0");
  // z = ((1 - c2) u - (1 - c1)) / sqrt(c1 + c2 u^2) with u = F^(1/3), c = 2 / (9 d): the larger
  // root of the quadratic in u.
  const double z = NormalQuantile(p);
  const double c1 = 2.0 / (9.0 * d1), c2 = 2.0 / (9.0 * d2);
  const double a = 1.0 - c2, b = 1.0 - c1;
  const double qa = a * a - z * z * c2, qb = -2.0 * a * b, qc = b * b - z * z * c1;
  if (!(qa > 0.0)) return std::numeric_limits<double>::infinity();  // d2 too small to bound
  const double u = (-qb + std::sqrt(std::max(0.0, qb * qb - 4.0 * qa * qc))) / (2.0 * qa);
  return u * u * u;
}

}  // namespace slamrig::slam

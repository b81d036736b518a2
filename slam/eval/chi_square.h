// Quantiles of the chi-square and F distributions, for consistency bounds (eval) and gates
// (fusion's data association and circle tests).
#pragma once

namespace slamrig::slam {

/// The `p` quantile of the chi-square distribution with `dof` degrees of freedom
/// (Wilson-Hilferty's start refined by Newton steps on the incomplete gamma function).
double ChiSquareQuantile(double p, double dof);

/// The `p` quantile (p >= 0.5) of the F distribution with (d1, d2) degrees of freedom, by
/// Paulson's cube-root normal approximation (Abramowitz and Stegun 26.6.15; within ~2 % of the
/// tables for d2 >= 3, cruder below).
double FQuantile(double p, double d1, double d2);

}  // namespace slamrig::slam

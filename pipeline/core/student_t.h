#pragma once
// Core: Student's t: how much wider a 95% bound must be when the standard error it multiplies was
// itself estimated from a few samples (a face's offset from the views that saw it, the table's
// height from its poses). With n samples the bound is t(n - 1) standard errors, not 1.96: 12.7
// from two samples, 2.1 from eighteen.

namespace boxd {

// The two-sided 95% quantile of the normal distribution.
inline constexpr double kNormal95 = 1.959964;

// Returns the two-sided 95% quantile of Student's t with `dof` >= 1 degrees of freedom: exact
// for one and two, the Cornish-Fisher expansion beyond (Abramowitz and Stegun 26.7.5: within
// 0.004 at three, 0.001 at four and five, 1e-4 from six on).
double StudentT95(int dof);

// Returns a standard error estimated from `samples` samples, widened so that kNormal95 times it
// is the 95% bound: `se` * StudentT95(samples - 1) / kNormal95 (`se` itself below two samples).
double WidenedForSamples(double se, int samples);

}  // namespace boxd

// The basis of cpfg's clamped uniform cubic B-splines, shared by function
// files (lsys/cpfg_function.h) and curve files (lsys/cpfg_curve.h).
#pragma once

namespace sylva::lsys {

// Knot k of the clamped uniform knots for n control points:
// 0 0 0 0 1 2 ... n-3 n-3 n-3 n-3.
inline double ClampedKnot(int k, int n) {
  if (k < 4) return 0;
  if (k > n - 1) return n - 3;
  return k - 3;
}

// Cox-de Boor basis N(k, order) at u over those knots (0/0 taken as 0).
inline double ClampedBasis(int k, int order, double u, int n) {
  if (order == 1) return ClampedKnot(k, n) <= u && u < ClampedKnot(k + 1, n) ? 1.0 : 0.0;
  double sum = 0;
  double div = ClampedKnot(k + order - 1, n) - ClampedKnot(k, n);
  if (div != 0) sum = (u - ClampedKnot(k, n)) / div * ClampedBasis(k, order - 1, u, n);
  div = ClampedKnot(k + order, n) - ClampedKnot(k + 1, n);
  if (div != 0) sum += (ClampedKnot(k + order, n) - u) / div * ClampedBasis(k + 1, order - 1, u, n);
  return sum;
}

}  // namespace sylva::lsys

#pragma once
// Blending of K unit dual quaternions with convex weights (docs/method.md §1, Eq. 4 and Algorithm 1).
//
//   DualQuatd b = Dlb<double>(qs, ws);                      // closed form, one normalisation
//   DibResult<double> r = Dib<double>(qs, ws, {1e-3, 32});   // iterative, exact blend
//   if (!r.converged) ...                                    // r.q is the last iterate
//
// Both align the sign of every input with a reference before summing (q and −q are the same
// transform): DLB uses the input of largest weight, DIB the current iterate. Neither allocates.
// Weights are not renormalised; callers pass convex weights (view_sphere.h produces them).

#include "anim/dual_quat.h"

#include <span>

namespace arview::anim {

template <class T>
struct DibOptions {
  T precision = T(1e-3);   // stop when ‖Σ w log(b* q)‖ < precision (the paper's p)
  int max_iterations = 32; // cap; `converged` is false if reached first
};

template <class T>
struct DibResult {
  DualQuat<T> q;
  int iterations = 0;
  bool converged = false;
};

// Dual quaternion linear blending: normalise(Σ w^k q̂^k). With an empty input or a sum whose real
// part vanishes (only possible with non-convex weights), returns identity.
template <class T>
DualQuat<T> Dlb(std::span<const DualQuat<T>> q, std::span<const T> w);

// Dual quaternion iterative blending, started from DLB.
template <class T>
DibResult<T> Dib(std::span<const DualQuat<T>> q, std::span<const T> w, const DibOptions<T>& options = {});

}  // namespace arview::anim

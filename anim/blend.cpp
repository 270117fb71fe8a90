#include "anim/blend.h"

#include <cassert>

namespace arview::anim {

template <class T>
DualQuat<T> Dlb(std::span<const DualQuat<T>> q, std::span<const T> w) {
  assert(q.size() == w.size());
  if (q.empty()) return DualQuat<T>();
  std::size_t pivot = 0;
  for (std::size_t k = 1; k < q.size(); ++k)
    if (w[k] > w[pivot]) pivot = k;
  Eigen::Matrix<T, 4, 1> r = Eigen::Matrix<T, 4, 1>::Zero(), d = Eigen::Matrix<T, 4, 1>::Zero();
  for (std::size_t k = 0; k < q.size(); ++k) {
    const T wk = q[k].RealDot(q[pivot]) < T(0) ? -w[k] : w[k];
    r += wk * q[k].real().coeffs();
    d += wk * q[k].dual().coeffs();
  }
  using Quat = typename DualQuat<T>::Quat;
  return DualQuat<T>(Quat(r), Quat(d)).Normalized();
}

template <class T>
DibResult<T> Dib(std::span<const DualQuat<T>> q, std::span<const T> w, const DibOptions<T>& options) {
  assert(q.size() == w.size());
  DibResult<T> result;
  result.q = Dlb(q, w);
  if (q.empty()) {
    result.converged = true;
    return result;
  }
  while (result.iterations < options.max_iterations) {
    const DualQuat<T> bc = result.q.Conjugate();
    DualLog<T> x;
    for (std::size_t k = 0; k < q.size(); ++k) {
      if (w[k] == T(0)) continue;
      // Log() itself picks the short way (non-negative real scalar), which is the alignment of
      // q^k with the current iterate b.
      x += (bc * q[k]).Log() * w[k];
    }
    ++result.iterations;
    result.q = (result.q * DualQuat<T>::Exp(x)).Normalized();
    if (x.Norm() < options.precision) {
      result.converged = true;
      break;
    }
  }
  return result;
}

template DualQuat<float> Dlb<float>(std::span<const DualQuat<float>>, std::span<const float>);
template DualQuat<double> Dlb<double>(std::span<const DualQuat<double>>, std::span<const double>);
template DibResult<float> Dib<float>(std::span<const DualQuat<float>>, std::span<const float>, const DibOptions<float>&);
template DibResult<double> Dib<double>(std::span<const DualQuat<double>>, std::span<const double>, const DibOptions<double>&);

}  // namespace arview::anim

// arbor-gen: 3x3 matrices and rigid transforms on std::array (the generator's only linear
// algebra; every function is a fixed, small number of flops).
#pragma once

#include <cmath>

#include "generator.hpp"

namespace arbor::gen {

inline Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        c[i][j] += a[i][k] * b[k][j];
  return c;
}
inline Vec3 mul(const Mat3& a, const Vec3& v) {
  Vec3 r{};
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      r[i] += a[i][k] * v[k];
  return r;
}
inline Mat3 transpose(const Mat3& a) {
  Mat3 t{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      t[i][j] = a[j][i];
  return t;
}
/// a * b: b's frame expressed through a.
inline Transform compose(const Transform& a, const Transform& b) {
  Transform c;
  c.R = mul(a.R, b.R);
  const Vec3 rp = mul(a.R, b.p);
  for (int i = 0; i < 3; ++i)
    c.p[i] = a.p[i] + rp[i];
  return c;
}
/// R I R^T: a tensor of a child frame expressed in its parent frame.
inline Mat3 rotate_tensor(const Mat3& R, const Mat3& I) {
  return mul(mul(R, I), transpose(R));
}
/// Rotation by angle q about a unit axis u (Rodrigues).
inline Mat3 axis_angle(const Vec3& u, double q) {
  const double c = std::cos(q), s = std::sin(q), t = 1 - c;
  return Mat3{{{t * u[0] * u[0] + c, t * u[0] * u[1] - s * u[2], t * u[0] * u[2] + s * u[1]},
               {t * u[0] * u[1] + s * u[2], t * u[1] * u[1] + c, t * u[1] * u[2] - s * u[0]},
               {t * u[0] * u[2] - s * u[1], t * u[1] * u[2] + s * u[0], t * u[2] * u[2] + c}}};
}
inline bool finite3(const Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// Eigen-decomposition of a symmetric 3x3 matrix: A = V diag(values) V^T, values ascending,
/// eigenvectors in the columns of V.
struct SymEigen {
  Vec3 values;
  Mat3 V;
};
/// Cyclic Jacobi, at most 64 sweeps (converges in a handful). A diagonal A gives V = identity
/// exactly.
SymEigen eigen_sym(Mat3 A);
/// V diag(values) V^T, exactly symmetric.
Mat3 from_eigen(const Mat3& V, const Vec3& values);
/// Rotation angle between two rotations from their Frobenius distance (accurate when small).
double rotation_distance(const Mat3& A, const Mat3& B);

}  // namespace arbor::gen

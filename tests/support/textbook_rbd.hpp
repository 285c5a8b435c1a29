// Test support: an independent, plain textbook rigid-body dynamics implementation (Featherstone's
// 6x6 spatial matrices, runtime loops, dynamic sizes), used to cross-check arbor's algorithms.
// Spatial vectors are [linear; angular] (as in arbor and Pinocchio). It shares nothing with
// include/arbor except the robot data it reads.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace arbor::textbook {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

inline Mat3 skew(const Vec3& x) {
  Mat3 K;
  K << 0, -x[2], x[1], x[2], 0, -x[0], -x[1], x[0], 0;
  return K;
}

/// Rigid transform x_parent = R x_child + p.
struct Transform {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  Transform operator*(const Transform& o) const { return {R * o.R, p + R * o.p}; }
};

/// Featherstone's motion transform from the parent frame to the child frame (child = parent*T).
inline Mat6 motion_parent_to_child(const Transform& T) {
  Mat6 X = Mat6::Zero();
  X.topLeftCorner<3, 3>() = T.R.transpose();
  X.topRightCorner<3, 3>() = -T.R.transpose() * skew(T.p);
  X.bottomRightCorner<3, 3>() = T.R.transpose();
  return X;
}

/// Motion cross product matrix.
inline Mat6 crm(const Vec6& m) {
  Mat6 X = Mat6::Zero();
  X.topLeftCorner<3, 3>() = skew(m.tail<3>());
  X.topRightCorner<3, 3>() = skew(m.head<3>());
  X.bottomRightCorner<3, 3>() = skew(m.tail<3>());
  return X;
}
/// Force cross product matrix.
inline Mat6 crf(const Vec6& m) {
  return -crm(m).transpose();
}

/// Runtime copy of a robot's data.
struct Model {
  int n = 0;
  std::vector<int> parent;
  std::vector<bool> revolute;
  std::vector<Vec3> axis;
  std::vector<Transform> placement;
  std::vector<Mat6> inertia;
  std::vector<int> frame_body;
  std::vector<Transform> frame_placement;
};

template <class R>
Model make_model() {
  Model m;
  m.n = R::nb;
  for (int i = 0; i < R::nb; ++i) {
    m.parent.push_back(R::parent[i]);
    const int k = int(R::joint_kind[i]);
    m.revolute.push_back(k < 4);
    m.axis.emplace_back(R::joint_axis[i][0], R::joint_axis[i][1], R::joint_axis[i][2]);
    Transform T;
    for (int r = 0; r < 3; ++r) {
      T.p[r] = R::joint_placement[i].p[r];
      for (int c = 0; c < 3; ++c)
        T.R(r, c) = R::joint_placement[i].R[r][c];
    }
    m.placement.push_back(T);
    const auto& Y = R::body_inertia[i];
    Vec3 c(Y.com[0], Y.com[1], Y.com[2]);
    Mat3 Ic;
    for (int r = 0; r < 3; ++r)
      for (int s = 0; s < 3; ++s)
        Ic(r, s) = Y.I[r][s];
    Mat6 I6 = Mat6::Zero();
    I6.topLeftCorner<3, 3>() = Y.mass * Mat3::Identity();
    I6.topRightCorner<3, 3>() = -Y.mass * skew(c);
    I6.bottomLeftCorner<3, 3>() = Y.mass * skew(c);
    I6.bottomRightCorner<3, 3>() = Ic - Y.mass * skew(c) * skew(c);
    m.inertia.push_back(I6);
  }
  for (int f = 0; f < R::nf; ++f) {
    m.frame_body.push_back(R::frames[f].body);
    Transform T;
    for (int r = 0; r < 3; ++r) {
      T.p[r] = R::frames[f].placement.p[r];
      for (int c = 0; c < 3; ++c)
        T.R(r, c) = R::frames[f].placement.R[r][c];
    }
    m.frame_placement.push_back(T);
  }
  return m;
}

/// Motion subspace of joint i.
inline Vec6 subspace(const Model& m, int i) {
  Vec6 S = Vec6::Zero();
  if (m.revolute[i])
    S.tail<3>() = m.axis[i];
  else
    S.head<3>() = m.axis[i];
  return S;
}

/// Placement of body i in its parent at configuration q_i.
inline Transform joint_transform(const Model& m, int i, double qi) {
  Transform J;
  if (m.revolute[i])
    J.R = Eigen::AngleAxisd(qi, m.axis[i]).toRotationMatrix();
  else
    J.p = qi * m.axis[i];
  return m.placement[i] * J;
}

/// World placements of the bodies.
inline std::vector<Transform> body_placements(const Model& m, const VecX& q) {
  std::vector<Transform> o(m.n);
  for (int i = 0; i < m.n; ++i) {
    const Transform l = joint_transform(m, i, q[i]);
    o[i] = m.parent[i] < 0 ? l : o[m.parent[i]] * l;
  }
  return o;
}

/// World placements of the operational frames.
inline std::vector<Transform> frame_placements(const Model& m, const VecX& q) {
  const auto o = body_placements(m, q);
  std::vector<Transform> f;
  for (std::size_t k = 0; k < m.frame_body.size(); ++k) {
    const int b = m.frame_body[k];
    f.push_back(b < 0 ? m.frame_placement[k] : o[b] * m.frame_placement[k]);
  }
  return f;
}

/// Body velocities in body frames.
inline std::vector<Vec6> body_velocities(const Model& m, const VecX& q, const VecX& v) {
  std::vector<Vec6> vel(m.n);
  for (int i = 0; i < m.n; ++i) {
    const Mat6 X = motion_parent_to_child(joint_transform(m, i, q[i]));
    const Vec6 vp = m.parent[i] < 0 ? Vec6::Zero().eval() : vel[m.parent[i]];
    vel[i] = X * vp + subspace(m, i) * v[i];
  }
  return vel;
}

/// Inverse dynamics (Featherstone's RNEA), fext in body frames (may be empty).
inline VecX rnea(const Model& m, const VecX& q, const VecX& v, const VecX& a, const Vec3& g,
                 const std::vector<Vec6>& fext = {}) {
  std::vector<Mat6> X(m.n);
  std::vector<Vec6> vel(m.n), acc(m.n), f(m.n);
  Vec6 a0 = Vec6::Zero();
  a0.head<3>() = -g;
  for (int i = 0; i < m.n; ++i) {
    X[i] = motion_parent_to_child(joint_transform(m, i, q[i]));
    const Vec6 S = subspace(m, i);
    const Vec6 vp = m.parent[i] < 0 ? Vec6::Zero().eval() : vel[m.parent[i]];
    const Vec6 ap = m.parent[i] < 0 ? a0 : acc[m.parent[i]];
    vel[i] = X[i] * vp + S * v[i];
    acc[i] = X[i] * ap + S * a[i] + crm(vel[i]) * S * v[i];
    f[i] = m.inertia[i] * acc[i] + crf(vel[i]) * m.inertia[i] * vel[i];
    if (!fext.empty())
      f[i] -= fext[i];
  }
  VecX tau(m.n);
  for (int i = m.n - 1; i >= 0; --i) {
    tau[i] = subspace(m, i).dot(f[i]);
    if (m.parent[i] >= 0)
      f[m.parent[i]] += X[i].transpose() * f[i];
  }
  return tau;
}

/// Mass matrix by columns of RNEA (zero velocity and gravity).
inline MatX crba(const Model& m, const VecX& q) {
  MatX M(m.n, m.n);
  const VecX zero = VecX::Zero(m.n);
  for (int k = 0; k < m.n; ++k) {
    VecX e = VecX::Zero(m.n);
    e[k] = 1;
    M.col(k) = rnea(m, q, zero, e, Vec3::Zero());
  }
  return M;
}

/// Forward dynamics by a dense solve M ddq = tau - nle.
inline VecX aba(const Model& m, const VecX& q, const VecX& v, const VecX& tau, const Vec3& g,
                const std::vector<Vec6>& fext = {}) {
  const MatX M = crba(m, q);
  const VecX b = rnea(m, q, v, VecX::Zero(m.n), g, fext);
  return M.ldlt().solve(tau - b);
}

/// World-frame Jacobian columns oMj S_j of every joint.
inline MatX joint_jacobians(const Model& m, const VecX& q) {
  const auto o = body_placements(m, q);
  MatX J(6, m.n);
  for (int j = 0; j < m.n; ++j) {
    const Vec6 S = subspace(m, j);
    const Vec3 w = o[j].R * S.tail<3>();
    J.col(j).head<3>() = o[j].R * S.head<3>() + o[j].p.cross(w);
    J.col(j).tail<3>() = w;
  }
  return J;
}

}  // namespace arbor::textbook

// Test-only references for the QP solvers, written with dynamic-size Eigen (never inside an
// allocation guard): the dense form of a QP, the KKT residuals of a candidate primal-dual point,
// and an exhaustive active-set enumeration that finds the optimal value of tiny convex QPs
// independently of the solvers under test.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <random>

#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::qp::test {

/// min 1/2 x'Hx + g'x  s.t. lbx <= x <= ubx, lba <= A x <= uba (dynamic sizes).
struct RefQp {
  Eigen::MatrixXd H;    ///< Hessian
  Eigen::VectorXd g;    ///< gradient
  Eigen::MatrixXd A;    ///< rows
  Eigen::VectorXd lbx;  ///< variable lower bounds
  Eigen::VectorXd ubx;  ///< variable upper bounds
  Eigen::VectorXd lba;  ///< row lower bounds
  Eigen::VectorXd uba;  ///< row upper bounds
};

/// Residuals of a primal-dual point (same definitions as the solvers' final check).
struct Kkt {
  double primal = 0;           ///< max violation
  double dual = 0;             ///< max |H x + g + lam_x + A' lam_a|
  double complementarity = 0;  ///< max min(|lam_i|, distance to the bound lam_i's sign selects)
  double objective = 0;        ///< 1/2 x'Hx + g'x
  double pscale = 1;           ///< 1 + max(|x|_inf, |A x|_inf): scale of primal and compl.
  double dscale = 1;           ///< 1 + max(|H x|, |g|, |A' lam + lam_x|)_inf: scale of dual
};

/// KKT residuals of (x, lam_x, lam_a) for q.
Kkt kkt_residuals(const RefQp& q, const Eigen::VectorXd& x, const Eigen::VectorXd& lx,
                  const Eigen::VectorXd& la);

/// Objective error allowed for a point with the residuals k (first-order bound:
/// primal residual * |lam|_1 + dual residual * |x|_1) plus a relative slack.
inline double objective_tolerance(const Kkt& k, const Eigen::VectorXd& x, const Eigen::VectorXd& lx,
                                  const Eigen::VectorXd& la, double rel) {
  return rel * (1 + std::abs(k.objective)) + k.primal * (lx.lpNorm<1>() + la.lpNorm<1>()) +
         k.complementarity * (lx.size() + la.size()) + k.dual * x.lpNorm<1>();
}

/// Result of the enumeration.
struct EnumResult {
  bool found = false;                                          ///< a KKT point exists
  double objective = std::numeric_limits<double>::infinity();  ///< optimal value
  Eigen::VectorXd x;                                           ///< a minimiser
};

/// Tries every working set (each inequality inactive, at its lower or at its upper bound;
/// equalities always active), solves the KKT system of each by a complete orthogonal
/// decomposition, keeps the points that are feasible with multipliers of the right sign and
/// returns the lowest objective. Exponential: only for tiny problems.
EnumResult enumerate_active_sets(const RefQp& q, double tol = 1e-8);

/// Dense form of an OcpQp in the solvers' flat layout (problem.hpp).
template <typename Qp>
RefQp to_ref(const Qp& qp) {
  constexpr int N = Qp::horizon, NX = Qp::nx, NU = Qp::nu, NG = Qp::ng, NGN = Qp::ngn;
  constexpr int NW = NX + NU, NV = Qp::nv, NA = Qp::na;
  RefQp r;
  r.H = Eigen::MatrixXd::Zero(NV, NV);
  r.g = Eigen::VectorXd::Zero(NV);
  r.A = Eigen::MatrixXd::Zero(NA, NV);
  r.lbx.resize(NV);
  r.ubx.resize(NV);
  r.lba.resize(NA);
  r.uba.resize(NA);
  for (int k = 0; k < N; ++k) {
    const auto& s = qp.stage[k];
    const int o = k * NW, w = k * (NX + NG);
    r.H.block(o, o, NX, NX) = s.Q.template cast<double>();
    r.H.block(o + NX, o, NU, NX) = s.S.template cast<double>();
    r.H.block(o, o + NX, NX, NU) = s.S.transpose().template cast<double>();
    r.H.block(o + NX, o + NX, NU, NU) = s.R.template cast<double>();
    r.g.segment(o, NX) = s.q.template cast<double>();
    r.g.segment(o + NX, NU) = s.r.template cast<double>();
    r.A.block(w, o + NW, NX, NX) = Eigen::MatrixXd::Identity(NX, NX);
    r.A.block(w, o, NX, NX) = -s.A.template cast<double>();
    r.A.block(w, o + NX, NX, NU) = -s.B.template cast<double>();
    r.lba.segment(w, NX) = s.b.template cast<double>();
    r.uba.segment(w, NX) = s.b.template cast<double>();
    r.A.block(w + NX, o, NG, NX) = s.C.template cast<double>();
    r.A.block(w + NX, o + NX, NG, NU) = s.D.template cast<double>();
    r.lba.segment(w + NX, NG) = s.lg.template cast<double>();
    r.uba.segment(w + NX, NG) = s.ug.template cast<double>();
    r.lbx.segment(o, NX) = s.lbx.template cast<double>();
    r.ubx.segment(o, NX) = s.ubx.template cast<double>();
    r.lbx.segment(o + NX, NU) = s.lbu.template cast<double>();
    r.ubx.segment(o + NX, NU) = s.ubu.template cast<double>();
  }
  const auto& t = qp.terminal;
  r.H.bottomRightCorner(NX, NX) = t.Q.template cast<double>();
  r.g.tail(NX) = t.q.template cast<double>();
  r.A.bottomRightCorner(NGN, NX) = t.C.template cast<double>();
  r.lba.tail(NGN) = t.lg.template cast<double>();
  r.uba.tail(NGN) = t.ug.template cast<double>();
  r.lbx.tail(NX) = t.lbx.template cast<double>();
  r.ubx.tail(NX) = t.ubx.template cast<double>();
  return r;
}

/// Copies a RefQp into a fixed-size dense problem (sizes must match).
template <typename Scalar, int NV, int NA>
void to_dense(const RefQp& r, DenseQpProblem<Scalar, NV, NA>& d) {
  d.H = r.H.cast<Scalar>();
  d.g = r.g.cast<Scalar>();
  d.A = r.A.cast<Scalar>();
  d.lbx = r.lbx.cast<Scalar>();
  d.ubx = r.ubx.cast<Scalar>();
  d.lba = r.lba.cast<Scalar>();
  d.uba = r.uba.cast<Scalar>();
}

/// Options of the random OCP generator.
struct RandomOcpOptions {
  bool strictly_convex = true;  ///< Hessian positive definite, else rank-deficient stages
  double bound_width = 1.0;     ///< typical distance of bounds from a feasible trajectory
  double inf_fraction = 0.2;    ///< fraction of bound sides set to +-inf
  double cost_scale = 3.0;      ///< magnitude of the linear cost (pushes against the bounds)
  bool lp = false;              ///< all Hessians zero (a linear program)
};

/// Fills qp with random data that is feasible by construction: a trajectory is simulated from a
/// fixed x_0 with random inputs and every bound and stage constraint is placed around it.
template <typename Qp>
void random_ocp(Qp& qp, std::mt19937& rng, const RandomOcpOptions& opt = {}) {
  using Scalar = typename decltype(qp.terminal.q)::Scalar;
  constexpr int N = Qp::horizon, NX = Qp::nx, NU = Qp::nu, NG = Qp::ng, NGN = Qp::ngn;
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> ud(0.0, 1.0);
  auto mat = [&](int r, int c, double s) {
    Eigen::MatrixXd m(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j)
        m(i, j) = s * nd(rng);
    return m;
  };
  auto lo = [&](double v) {
    return ud(rng) < opt.inf_fraction ? -inf : v - opt.bound_width * ud(rng);
  };
  auto hi = [&](double v) {
    return ud(rng) < opt.inf_fraction ? inf : v + opt.bound_width * ud(rng);
  };
  Eigen::VectorXd x = mat(NX, 1, 1.0);
  for (int k = 0; k < N; ++k) {
    auto& s = qp.stage[k];
    const int nw = NX + NU;
    Eigen::MatrixXd L = mat(nw, nw, 1.0);
    Eigen::MatrixXd H = L * L.transpose() / nw;
    if (opt.strictly_convex) {
      H += 0.1 * Eigen::MatrixXd::Identity(nw, nw);
    } else {
      Eigen::MatrixXd F = mat(nw, 1 + nw / 3, 1.0);  // low rank
      H = F * F.transpose() / nw;
      if (NX > 1) {  // a state without cost (like a path parameter)
        H.row(NX - 1).setZero();
        H.col(NX - 1).setZero();
      }
    }
    if (opt.lp)
      H.setZero();
    s.Q = H.topLeftCorner(NX, NX).cast<Scalar>();
    s.S = H.bottomLeftCorner(NU, NX).cast<Scalar>();
    s.R = H.bottomRightCorner(NU, NU).cast<Scalar>();
    s.q = mat(NX, 1, opt.cost_scale).template cast<Scalar>();
    s.r = mat(NU, 1, opt.cost_scale).template cast<Scalar>();
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(NX, NX) + mat(NX, NX, 0.2);
    Eigen::MatrixXd B = mat(NX, NU, 0.5);
    Eigen::VectorXd b = mat(NX, 1, 0.1);
    s.A = A.cast<Scalar>();
    s.B = B.cast<Scalar>();
    s.b = b.cast<Scalar>();
    Eigen::VectorXd u = mat(NU, 1, 1.0);
    Eigen::MatrixXd C = mat(NG, NX, 1.0), D = mat(NG, NU, 1.0);
    s.C = C.cast<Scalar>();
    s.D = D.cast<Scalar>();
    Eigen::VectorXd gv = C * x + D * u;
    for (int j = 0; j < NG; ++j) {
      s.lg(j) = static_cast<Scalar>(lo(gv(j)));
      s.ug(j) = static_cast<Scalar>(hi(gv(j)));
    }
    for (int i = 0; i < NX; ++i) {
      if (k == 0) {
        s.lbx(i) = s.ubx(i) = static_cast<Scalar>(x(i));
      } else {
        s.lbx(i) = static_cast<Scalar>(lo(x(i)));
        s.ubx(i) = static_cast<Scalar>(hi(x(i)));
      }
    }
    for (int i = 0; i < NU; ++i) {
      s.lbu(i) = static_cast<Scalar>(lo(u(i)));
      s.ubu(i) = static_cast<Scalar>(hi(u(i)));
    }
    // simulate with the stored (possibly rounded) data so the trajectory stays feasible
    x = (s.A.template cast<double>() * x + s.B.template cast<double>() * u +
         s.b.template cast<double>())
            .eval();
  }
  auto& t = qp.terminal;
  Eigen::MatrixXd L = mat(NX, NX, 1.0);
  Eigen::MatrixXd H = L * L.transpose() / NX;
  if (opt.strictly_convex) {
    H += 0.1 * Eigen::MatrixXd::Identity(NX, NX);
  } else if (NX > 1) {
    H.row(NX - 1).setZero();
    H.col(NX - 1).setZero();
  }
  if (opt.lp)
    H.setZero();
  t.Q = H.cast<Scalar>();
  t.q = mat(NX, 1, opt.cost_scale).template cast<Scalar>();
  Eigen::MatrixXd C = mat(NGN, NX, 1.0);
  t.C = C.cast<Scalar>();
  Eigen::VectorXd gv = C * x;
  for (int j = 0; j < NGN; ++j) {
    t.lg(j) = static_cast<Scalar>(lo(gv(j)));
    t.ug(j) = static_cast<Scalar>(hi(gv(j)));
  }
  for (int i = 0; i < NX; ++i) {
    t.lbx(i) = static_cast<Scalar>(lo(x(i)));
    t.ubx(i) = static_cast<Scalar>(hi(x(i)));
  }
}

}  // namespace arbor::qp::test

// arbor::qp: the data of the two QP forms the solvers take (data only, no code): a dense QP of
// fixed size (DenseQpProblem) and the optimal-control QP with stage structure (OcpQp).
//
// Dense:
//   min 1/2 x'Hx + g'x   s.t.  lbx <= x <= ubx,  lba <= A x <= uba       (x in R^NV, A: NA x NV)
//
// Stage-structured:
//   min  sum_{k<N} 1/2 [x_k;u_k]' [Q_k S_k'; S_k R_k] [x_k;u_k] + [q_k;r_k]'[x_k;u_k]
//        + 1/2 x_N' Q_N x_N + q_N' x_N
//   s.t. x_{k+1} = A_k x_k + B_k u_k + b_k                      k = 0..N-1
//        lbx_k <= x_k <= ubx_k,  lbu_k <= u_k <= ubu_k           (x_0 given: lbx_0 = ubx_0)
//        lg_k <= C_k x_k + D_k u_k <= ug_k                       (NG rows per path stage)
//        lbx_N <= x_N <= ubx_N,  lg_N <= C_N x_N <= ug_N         (NGN rows at the terminal stage)
// Bounds may be +-inf; equal lower and upper bounds make an equality (always active).
// Every size is a template parameter; the path stages share NX, NU, NG and the terminal stage has
// its own NGN (and no input).
//
// Flat layout used by the solvers (and by the tests to build the equivalent dense QP):
//   variables  v = [x_0, u_0, x_1, u_1, ..., x_{N-1}, u_{N-1}, x_N]      NV = N (NX+NU) + NX
//   rows       a = [dyn_0, gen_0, dyn_1, gen_1, ..., dyn_{N-1}, gen_{N-1}, gen_N]
//              NA = N (NX+NG) + NGN,  dyn_k = x_{k+1} - A_k x_k - B_k u_k in [b_k, b_k],
//              gen_k = C_k x_k + D_k u_k in [lg_k, ug_k].
//
// Copied or referenced (one rule for both solvers): setup(p) keeps a pointer to p, which must
// outlive the solver's use of it.
// - Vectors are copied: the gradients (g; q, r), the dynamics offsets b and every bound are read
//   by setup() and update() into the solver's flat arrays. A change to them takes effect at the
//   next update().
// - Matrices are referenced: H, A; Q, S, R, A, B, C, D are read through the pointer by every
//   solve() (never copied). A change to them takes effect at the next solve(), but only setup()
//   and update() check them (finite, convex): after changing any data, call update().
#pragma once

#include <Eigen/Core>
#include <array>

namespace arbor::qp {

/// Data of a dense QP (see the top of this file).
template <typename Scalar, int NV, int NA>
struct DenseQpProblem {
  Eigen::Matrix<Scalar, NV, NV> H;   ///< symmetric positive semidefinite Hessian
  Eigen::Matrix<Scalar, NV, 1> g;    ///< linear cost
  Eigen::Matrix<Scalar, NA, NV> A;   ///< constraint matrix
  Eigen::Matrix<Scalar, NV, 1> lbx;  ///< variable lower bounds (may be -inf)
  Eigen::Matrix<Scalar, NV, 1> ubx;  ///< variable upper bounds (may be +inf)
  Eigen::Matrix<Scalar, NA, 1> lba;  ///< row lower bounds (may be -inf)
  Eigen::Matrix<Scalar, NA, 1> uba;  ///< row upper bounds (may be +inf)
};

/// One path stage k < N of an OcpQp.
template <typename Scalar, int NX, int NU, int NG>
struct OcpStage {
  Eigen::Matrix<Scalar, NX, NX> Q;   ///< state Hessian
  Eigen::Matrix<Scalar, NU, NX> S;   ///< input-state cross Hessian
  Eigen::Matrix<Scalar, NU, NU> R;   ///< input Hessian
  Eigen::Matrix<Scalar, NX, 1> q;    ///< state gradient
  Eigen::Matrix<Scalar, NU, 1> r;    ///< input gradient
  Eigen::Matrix<Scalar, NX, NX> A;   ///< dynamics: state matrix
  Eigen::Matrix<Scalar, NX, NU> B;   ///< dynamics: input matrix
  Eigen::Matrix<Scalar, NX, 1> b;    ///< dynamics: offset
  Eigen::Matrix<Scalar, NG, NX> C;   ///< path constraints: state part
  Eigen::Matrix<Scalar, NG, NU> D;   ///< path constraints: input part
  Eigen::Matrix<Scalar, NG, 1> lg;   ///< path constraints: lower bounds
  Eigen::Matrix<Scalar, NG, 1> ug;   ///< path constraints: upper bounds
  Eigen::Matrix<Scalar, NX, 1> lbx;  ///< state lower bounds
  Eigen::Matrix<Scalar, NX, 1> ubx;  ///< state upper bounds
  Eigen::Matrix<Scalar, NU, 1> lbu;  ///< input lower bounds
  Eigen::Matrix<Scalar, NU, 1> ubu;  ///< input upper bounds
};

/// The terminal stage N of an OcpQp.
template <typename Scalar, int NX, int NGN>
struct OcpTerminal {
  Eigen::Matrix<Scalar, NX, NX> Q;   ///< terminal Hessian
  Eigen::Matrix<Scalar, NX, 1> q;    ///< terminal gradient
  Eigen::Matrix<Scalar, NGN, NX> C;  ///< terminal constraints
  Eigen::Matrix<Scalar, NGN, 1> lg;  ///< terminal constraints: lower bounds
  Eigen::Matrix<Scalar, NGN, 1> ug;  ///< terminal constraints: upper bounds
  Eigen::Matrix<Scalar, NX, 1> lbx;  ///< terminal state lower bounds
  Eigen::Matrix<Scalar, NX, 1> ubx;  ///< terminal state upper bounds
};

/// Optimal-control QP of horizon N (see the top of this file).
template <typename Scalar, int N, int NX, int NU, int NG, int NGN = NG>
struct OcpQp {
  static_assert(N >= 1 && NX >= 1 && NU >= 0 && NG >= 0 && NGN >= 0, "invalid OCP sizes");
  static constexpr int horizon = N;               ///< number of path stages
  static constexpr int nx = NX;                   ///< states per stage
  static constexpr int nu = NU;                   ///< inputs per path stage
  static constexpr int ng = NG;                   ///< general constraints per path stage
  static constexpr int ngn = NGN;                 ///< general constraints at the terminal stage
  static constexpr int nw = NX + NU;              ///< variables per path stage
  static constexpr int nv = N * (NX + NU) + NX;   ///< variables in total
  static constexpr int na = N * (NX + NG) + NGN;  ///< constraint rows in total (dynamics too)
  using Stage = OcpStage<Scalar, NX, NU, NG>;     ///< path stage data
  using Terminal = OcpTerminal<Scalar, NX, NGN>;  ///< terminal stage data

  std::array<Stage, N> stage;  ///< path stages 0..N-1
  Terminal terminal;           ///< terminal stage N

  /// Offset of x_k in the flat variable vector (k = 0..N).
  static constexpr int state_offset(int k) { return k * nw; }
  /// Offset of u_k in the flat variable vector (k = 0..N-1).
  static constexpr int input_offset(int k) { return k * nw + NX; }
  /// Offset of dyn_k (k < N) in the flat row vector.
  static constexpr int dynamics_offset(int k) { return k * (NX + NG); }
  /// Offset of gen_k (k = 0..N; gen_N is the terminal block) in the flat row vector.
  static constexpr int constraint_offset(int k) {
    return k < N ? k * (NX + NG) + NX : N * (NX + NG);
  }
};

}  // namespace arbor::qp

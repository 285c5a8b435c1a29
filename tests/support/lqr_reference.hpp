// Test support (host only, not part of the library): finite-horizon discrete-time LQR, the
// reference for NMPC tests on linear-quadratic problems. Two independent computations of the same
// optimum: a backward Riccati recursion (lqr_riccati) and the condensed dense QP solved by one
// LDLT factorisation (lqr_dense_qp). Dynamic-size Eigen; allocates freely.
//
//   min  sum_{k<N} ( 1/2 x_k'Q_k x_k + u_k'S_k x_k + 1/2 u_k'R_k u_k + q_k'x_k + r_k'u_k )
//        + 1/2 x_N'P_N x_N + p_N'x_N
//   s.t. x_{k+1} = A_k x_k + B_k u_k + b_k,   x_0 given,
//
// with the conventions of arbor's OcpQp (include/arbor/qp/problem.hpp): S_k is nu x nx (the
// input-state cross Hessian, stage Hessian [Q S'; S R]), b_k the dynamics offset. Every per-stage
// list (A, B, b, Q, R, S, q, r) holds either one element (the same for every stage) or N; the
// optional ones (b, S, q, r) may be empty (zero). R_k + B_k'P_{k+1}B_k must be positive definite.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace arbor::test {

struct LqrProblem {
  int N = 0;                          ///< horizon (number of inputs), >= 1
  std::vector<Eigen::MatrixXd> A, B;  ///< dynamics (1 or N each)
  std::vector<Eigen::VectorXd> b;     ///< dynamics offset (0, 1 or N)
  std::vector<Eigen::MatrixXd> Q, R;  ///< stage Hessians (1 or N each)
  std::vector<Eigen::MatrixXd> S;     ///< nu x nx cross terms (0, 1 or N)
  std::vector<Eigen::VectorXd> q, r;  ///< stage gradients (0, 1 or N each)
  Eigen::MatrixXd P_N;                ///< terminal Hessian (nx x nx)
  Eigen::VectorXd p_N;                ///< terminal gradient (empty: zero)
  Eigen::VectorXd x0;                 ///< initial state

  int nx() const { return static_cast<int>(x0.size()); }
  int nu() const { return static_cast<int>(B.at(0).cols()); }

  // Stage-k data (constant lists repeat their one element; empty optional ones are zero).
  const Eigen::MatrixXd& A_at(int k) const { return pick(A, k); }
  const Eigen::MatrixXd& B_at(int k) const { return pick(B, k); }
  const Eigen::MatrixXd& Q_at(int k) const { return pick(Q, k); }
  const Eigen::MatrixXd& R_at(int k) const { return pick(R, k); }
  Eigen::VectorXd b_at(int k) const { return b.empty() ? Eigen::VectorXd::Zero(nx()) : pick(b, k); }
  Eigen::MatrixXd S_at(int k) const {
    return S.empty() ? Eigen::MatrixXd::Zero(nu(), nx()) : pick(S, k);
  }
  Eigen::VectorXd q_at(int k) const { return q.empty() ? Eigen::VectorXd::Zero(nx()) : pick(q, k); }
  Eigen::VectorXd r_at(int k) const { return r.empty() ? Eigen::VectorXd::Zero(nu()) : pick(r, k); }
  Eigen::VectorXd p_N_or_zero() const {
    return p_N.size() == 0 ? Eigen::VectorXd::Zero(nx()) : p_N;
  }

  /// Throws std::invalid_argument naming the first inconsistent size.
  void check() const {
    auto fail = [](const std::string& what) { throw std::invalid_argument("LqrProblem: " + what); };
    if (N < 1)
      fail("N < 1");
    const int n = nx();
    if (n < 1)
      fail("x0 empty");
    if (B.empty())
      fail("B empty");
    const int m = nu();
    auto count = [&](std::size_t size, bool optional, const char* name) {
      if (!(size == 1 || size == static_cast<std::size_t>(N) || (optional && size == 0))) {
        fail(std::string(name) + " must hold 1 or N elements");
      }
    };
    count(A.size(), false, "A");
    count(B.size(), false, "B");
    count(Q.size(), false, "Q");
    count(R.size(), false, "R");
    count(b.size(), true, "b");
    count(S.size(), true, "S");
    count(q.size(), true, "q");
    count(r.size(), true, "r");
    for (const auto& M : A) {
      if (M.rows() != n || M.cols() != n)
        fail("A size");
    }
    for (const auto& M : B) {
      if (M.rows() != n || M.cols() != m)
        fail("B size");
    }
    for (const auto& M : Q) {
      if (M.rows() != n || M.cols() != n)
        fail("Q size");
    }
    for (const auto& M : R) {
      if (M.rows() != m || M.cols() != m)
        fail("R size");
    }
    for (const auto& M : S) {
      if (M.rows() != m || M.cols() != n)
        fail("S size (nu x nx)");
    }
    for (const auto& v : b) {
      if (v.size() != n)
        fail("b size");
    }
    for (const auto& v : q) {
      if (v.size() != n)
        fail("q size");
    }
    for (const auto& v : r) {
      if (v.size() != m)
        fail("r size");
    }
    if (P_N.rows() != n || P_N.cols() != n)
      fail("P_N size");
    if (p_N.size() != 0 && p_N.size() != n)
      fail("p_N size");
  }

 private:
  template <typename T>
  static const T& pick(const std::vector<T>& v, int k) {
    return v.size() == 1 ? v[0] : v.at(static_cast<std::size_t>(k));
  }
};

/// An LQR solution: trajectories, the optimal cost, and (Riccati only) the feedback law
/// u_k = K_k x_k + k_k and the cost-to-go V_k(x) = 1/2 x'P_k x + p_k'x + c_k (P, p of size N+1).
struct LqrSolution {
  std::vector<Eigen::VectorXd> x;  ///< x_0 .. x_N
  std::vector<Eigen::VectorXd> u;  ///< u_0 .. u_{N-1}
  double cost = 0;                 ///< objective at (x, u)
  std::vector<Eigen::MatrixXd> K;  ///< feedback gains (Riccati only)
  std::vector<Eigen::VectorXd> k;  ///< feedforward terms (Riccati only)
  std::vector<Eigen::MatrixXd> P;  ///< cost-to-go Hessians P_0 .. P_N (Riccati only)
  std::vector<Eigen::VectorXd> p;  ///< cost-to-go gradients p_0 .. p_N (Riccati only)
};

/// The objective of a trajectory (x: N+1 states, u: N inputs).
inline double lqr_cost(const LqrProblem& pr, const std::vector<Eigen::VectorXd>& x,
                       const std::vector<Eigen::VectorXd>& u) {
  double c = 0;
  for (int k = 0; k < pr.N; ++k) {
    const Eigen::VectorXd& xk = x[static_cast<std::size_t>(k)];
    const Eigen::VectorXd& uk = u[static_cast<std::size_t>(k)];
    c += 0.5 * xk.dot(pr.Q_at(k) * xk) + uk.dot(pr.S_at(k) * xk) + 0.5 * uk.dot(pr.R_at(k) * uk) +
         pr.q_at(k).dot(xk) + pr.r_at(k).dot(uk);
  }
  const Eigen::VectorXd& xN = x[static_cast<std::size_t>(pr.N)];
  return c + 0.5 * xN.dot(pr.P_N * xN) + pr.p_N_or_zero().dot(xN);
}

/// Simulates x_{k+1} = A_k x_k + B_k u_k + b_k from x0.
inline std::vector<Eigen::VectorXd> lqr_rollout(const LqrProblem& pr,
                                                const std::vector<Eigen::VectorXd>& u) {
  std::vector<Eigen::VectorXd> x(static_cast<std::size_t>(pr.N) + 1);
  x[0] = pr.x0;
  for (int k = 0; k < pr.N; ++k) {
    const auto i = static_cast<std::size_t>(k);
    x[i + 1] = pr.A_at(k) * x[i] + pr.B_at(k) * u[i] + pr.b_at(k);
  }
  return x;
}

/// Backward Riccati recursion (value function V_k(x) = 1/2 x'P_k x + p_k'x + const):
///   P_N, p_N given;  for k = N-1 .. 0, with P = P_{k+1}, p = p_{k+1}:
///   Ruu = R + B'PB,  Rux = S + B'PA,  ru = r + B'(P b + p)
///   K_k = -Ruu^{-1} Rux,  k_k = -Ruu^{-1} ru
///   P_k = Q + A'PA + Rux'K_k,  p_k = q + A'(P b + p) + Rux'k_k
/// then the forward pass u_k = K_k x_k + k_k. Throws std::runtime_error when some Ruu is not
/// positive definite.
inline LqrSolution lqr_riccati(const LqrProblem& pr) {
  pr.check();
  const int N = pr.N;
  const auto sN = static_cast<std::size_t>(N);
  LqrSolution s;
  s.P.resize(sN + 1);
  s.p.resize(sN + 1);
  s.K.resize(sN);
  s.k.resize(sN);
  s.P[sN] = pr.P_N;
  s.p[sN] = pr.p_N_or_zero();
  for (int k = N - 1; k >= 0; --k) {
    const auto i = static_cast<std::size_t>(k);
    const Eigen::MatrixXd& A = pr.A_at(k);
    const Eigen::MatrixXd& B = pr.B_at(k);
    const Eigen::MatrixXd& P = s.P[i + 1];
    const Eigen::VectorXd Pb_p = P * pr.b_at(k) + s.p[i + 1];
    const Eigen::MatrixXd Ruu = pr.R_at(k) + B.transpose() * P * B;
    const Eigen::MatrixXd Rux = pr.S_at(k) + B.transpose() * P * A;
    const Eigen::VectorXd ru = pr.r_at(k) + B.transpose() * Pb_p;
    const Eigen::LLT<Eigen::MatrixXd> llt(Ruu);
    if (llt.info() != Eigen::Success) {
      throw std::runtime_error("lqr_riccati: R + B'PB not positive definite at stage " +
                               std::to_string(k));
    }
    s.K[i] = -llt.solve(Rux);
    s.k[i] = -llt.solve(ru);
    Eigen::MatrixXd Pk = pr.Q_at(k) + A.transpose() * P * A + Rux.transpose() * s.K[i];
    s.P[i] = 0.5 * (Pk + Pk.transpose());
    s.p[i] = pr.q_at(k) + A.transpose() * Pb_p + Rux.transpose() * s.k[i];
  }
  s.x.resize(sN + 1);
  s.u.resize(sN);
  s.x[0] = pr.x0;
  for (int k = 0; k < N; ++k) {
    const auto i = static_cast<std::size_t>(k);
    s.u[i] = s.K[i] * s.x[i] + s.k[i];
    s.x[i + 1] = pr.A_at(k) * s.x[i] + pr.B_at(k) * s.u[i] + pr.b_at(k);
  }
  s.cost = lqr_cost(pr, s.x, s.u);
  return s;
}

/// The same problem as one dense QP in the inputs U = (u_0, .., u_{N-1}) (condensed: the states
/// are X = Sx x0 + Su U + Sb from the dynamics), min 1/2 U'H U + g'U, solved by H U = -g with
/// Eigen's LDLT. Throws std::runtime_error when H is not positive definite.
inline LqrSolution lqr_dense_qp(const LqrProblem& pr) {
  pr.check();
  const int N = pr.N, nx = pr.nx(), nu = pr.nu();
  const int NX = (N + 1) * nx, NU = N * nu;
  // X = Sx x0 + Su U + Sb
  Eigen::MatrixXd Su = Eigen::MatrixXd::Zero(NX, NU);
  Eigen::VectorXd X0 = Eigen::VectorXd::Zero(NX);  // Sx x0 + Sb
  X0.head(nx) = pr.x0;
  for (int k = 0; k < N; ++k) {
    const Eigen::MatrixXd& A = pr.A_at(k);
    X0.segment((k + 1) * nx, nx) = A * X0.segment(k * nx, nx) + pr.b_at(k);
    Su.block((k + 1) * nx, 0, nx, NU) = A * Su.block(k * nx, 0, nx, NU);
    Su.block((k + 1) * nx, k * nu, nx, nu) += pr.B_at(k);
  }
  // Cost 1/2 X'Qb X + U'Sb X + 1/2 U'Rb U + qb'X + rb'U (block diagonal stage data).
  Eigen::MatrixXd Qb = Eigen::MatrixXd::Zero(NX, NX);
  Eigen::MatrixXd Rb = Eigen::MatrixXd::Zero(NU, NU);
  Eigen::MatrixXd Sb = Eigen::MatrixXd::Zero(NU, NX);
  Eigen::VectorXd qb(NX), rb(NU);
  for (int k = 0; k < N; ++k) {
    Qb.block(k * nx, k * nx, nx, nx) = pr.Q_at(k);
    Rb.block(k * nu, k * nu, nu, nu) = pr.R_at(k);
    Sb.block(k * nu, k * nx, nu, nx) = pr.S_at(k);
    qb.segment(k * nx, nx) = pr.q_at(k);
    rb.segment(k * nu, nu) = pr.r_at(k);
  }
  Qb.block(N * nx, N * nx, nx, nx) = pr.P_N;
  qb.segment(N * nx, nx) = pr.p_N_or_zero();
  // Substituting X: H = Su'Qb Su + Rb + Sb Su + Su'Sb',  g = Su'(Qb X0 + qb) + Sb X0 + rb.
  Eigen::MatrixXd H = Su.transpose() * Qb * Su + Rb + Sb * Su + Su.transpose() * Sb.transpose();
  H = 0.5 * (H + H.transpose()).eval();
  const Eigen::VectorXd g = Su.transpose() * (Qb * X0 + qb) + Sb * X0 + rb;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || (ldlt.vectorD().array() <= 0).any()) {
    throw std::runtime_error("lqr_dense_qp: condensed Hessian not positive definite");
  }
  const Eigen::VectorXd U = ldlt.solve(-g);
  const Eigen::VectorXd X = X0 + Su * U;
  LqrSolution s;
  s.x.resize(static_cast<std::size_t>(N) + 1);
  s.u.resize(static_cast<std::size_t>(N));
  for (int k = 0; k <= N; ++k)
    s.x[static_cast<std::size_t>(k)] = X.segment(k * nx, nx);
  for (int k = 0; k < N; ++k)
    s.u[static_cast<std::size_t>(k)] = U.segment(k * nu, nu);
  s.cost = lqr_cost(pr, s.x, s.u);
  return s;
}

}  // namespace arbor::test

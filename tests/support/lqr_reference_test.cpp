// The LQR reference (lqr_reference.hpp): Riccati recursion against the condensed dense QP,
// against a one-step closed form and against the scalar algebraic Riccati equation.
#include "lqr_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace arbor::test {
namespace {

struct Lcg {
  std::uint64_t s;
  double next() {  // uniform in [-1, 1)
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(s >> 11) * (2.0 / 9007199254740992.0) - 1.0;
  }
  Eigen::MatrixXd matrix(int r, int c) {
    Eigen::MatrixXd M(r, c);
    for (int i = 0; i < r; ++i) {
      for (int j = 0; j < c; ++j)
        M(i, j) = next();
    }
    return M;
  }
};

// A random problem with every term present, per stage. The stage Hessians [Q S'; S R] are
// positive definite (a Gram matrix plus a multiple of the identity).
LqrProblem random_problem(std::uint64_t seed, int N, int nx, int nu) {
  Lcg rng{seed};
  LqrProblem pr;
  pr.N = N;
  for (int k = 0; k < N; ++k) {
    pr.A.push_back(Eigen::MatrixXd::Identity(nx, nx) + 0.3 * rng.matrix(nx, nx));
    pr.B.push_back(rng.matrix(nx, nu));
    pr.b.push_back(0.1 * rng.matrix(nx, 1));
    const Eigen::MatrixXd M = rng.matrix(nx + nu, nx + nu);
    const Eigen::MatrixXd W = M.transpose() * M + 0.2 * Eigen::MatrixXd::Identity(nx + nu, nx + nu);
    pr.Q.push_back(W.topLeftCorner(nx, nx));
    pr.S.push_back(W.bottomLeftCorner(nu, nx));
    pr.R.push_back(W.bottomRightCorner(nu, nu));
    pr.q.push_back(rng.matrix(nx, 1));
    pr.r.push_back(rng.matrix(nu, 1));
  }
  const Eigen::MatrixXd M = rng.matrix(nx, nx);
  pr.P_N = M.transpose() * M + Eigen::MatrixXd::Identity(nx, nx);
  pr.p_N = rng.matrix(nx, 1);
  pr.x0 = rng.matrix(nx, 1);
  return pr;
}

double max_diff(const std::vector<Eigen::VectorXd>& a, const std::vector<Eigen::VectorXd>& b) {
  EXPECT_EQ(a.size(), b.size());
  double d = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    d = std::max(d, (a[i] - b[i]).lpNorm<Eigen::Infinity>());
  }
  return d;
}

TEST(LqrReference, RiccatiMatchesDenseQp) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const LqrProblem pr = random_problem(seed, 10, 4, 2);
    const LqrSolution ric = lqr_riccati(pr);
    const LqrSolution qp = lqr_dense_qp(pr);
    EXPECT_LT(max_diff(ric.u, qp.u), 1e-9) << seed;
    EXPECT_LT(max_diff(ric.x, qp.x), 1e-9) << seed;
    EXPECT_NEAR(ric.cost, qp.cost, 1e-9 * std::max(1.0, std::abs(qp.cost))) << seed;
    // The dynamics hold, and the trajectory is not trivial.
    EXPECT_LT(max_diff(lqr_rollout(pr, qp.u), qp.x), 1e-12);
    EXPECT_GT(ric.u[0].norm(), 1e-3);
  }
}

TEST(LqrReference, OptimalityAgainstPerturbations) {
  const LqrProblem pr = random_problem(42, 8, 3, 2);
  const LqrSolution s = lqr_riccati(pr);
  // Directional derivative 0 and a cost increase for +-h in every input coordinate.
  const double h = 1e-3;
  for (int k = 0; k < pr.N; ++k) {
    for (int j = 0; j < pr.nu(); ++j) {
      std::vector<Eigen::VectorXd> up = s.u, um = s.u;
      up[k](j) += h;
      um[k](j) -= h;
      const double cp = lqr_cost(pr, lqr_rollout(pr, up), up);
      const double cm = lqr_cost(pr, lqr_rollout(pr, um), um);
      EXPECT_GT(cp, s.cost);
      EXPECT_GT(cm, s.cost);
      EXPECT_NEAR((cp - cm) / (2 * h), 0.0, 1e-8) << k << "," << j;
    }
  }
}

TEST(LqrReference, ConstantDataEqualsRepeatedStages) {
  LqrProblem one = random_problem(3, 1, 3, 1);
  one.N = 7;
  LqrProblem many = one;
  for (auto* list : {&many.A, &many.B, &many.Q, &many.R, &many.S})
    list->assign(7, list->front());
  for (auto* list : {&many.b, &many.q, &many.r})
    list->assign(7, list->front());
  const LqrSolution a = lqr_riccati(one), b = lqr_riccati(many);
  EXPECT_EQ(max_diff(a.u, b.u), 0.0);
  EXPECT_LT(max_diff(lqr_dense_qp(one).u, b.u), 1e-10);
  // Optional terms absent: zero.
  LqrProblem plain = one;
  plain.b.clear();
  plain.S.clear();
  plain.q.clear();
  plain.r.clear();
  plain.p_N.resize(0);
  LqrProblem zeros = one;
  zeros.b = {Eigen::VectorXd::Zero(3)};
  zeros.S = {Eigen::MatrixXd::Zero(1, 3)};
  zeros.q = {Eigen::VectorXd::Zero(3)};
  zeros.r = {Eigen::VectorXd::Zero(1)};
  zeros.p_N = Eigen::VectorXd::Zero(3);
  EXPECT_LT(max_diff(lqr_riccati(plain).u, lqr_riccati(zeros).u), 1e-15);
  EXPECT_LT(max_diff(lqr_dense_qp(plain).u, lqr_riccati(zeros).u), 1e-10);
}

// N = 1: min over u of stage(x0, u) + V_N(A x0 + B u + b), a quadratic in u whose minimiser is
// u = -(R + B'P B)^{-1} ((S + B'P A) x0 + r + B'(P b + p)), written here directly.
TEST(LqrReference, OneStepClosedForm) {
  const LqrProblem pr = random_problem(9, 1, 3, 2);
  const Eigen::MatrixXd &A = pr.A[0], &B = pr.B[0], &P = pr.P_N;
  const Eigen::VectorXd u = -(pr.R[0] + B.transpose() * P * B).inverse() *
                            ((pr.S[0] + B.transpose() * P * A) * pr.x0 + pr.r[0] +
                             B.transpose() * (P * pr.b[0] + pr.p_N));
  const LqrSolution ric = lqr_riccati(pr);
  const LqrSolution qp = lqr_dense_qp(pr);
  EXPECT_LT((ric.u[0] - u).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((qp.u[0] - u).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT((ric.x[1] - (A * pr.x0 + B * u + pr.b[0])).lpNorm<Eigen::Infinity>(), 1e-12);
}

// Scalar a = b = q = r = 1 (cost 1/2 x^2 + 1/2 u^2 per stage): the algebraic Riccati equation
// p = 1 + p - p^2 / (1 + p) has the root p = (1 + sqrt 5) / 2, the gain k = -p / (1 + p). A long
// horizon from P_N = 0 converges to it.
TEST(LqrReference, ScalarRiccatiConvergesToGoldenRatio) {
  LqrProblem pr;
  pr.N = 60;
  pr.A = {Eigen::MatrixXd::Ones(1, 1)};
  pr.B = {Eigen::MatrixXd::Ones(1, 1)};
  pr.Q = {Eigen::MatrixXd::Ones(1, 1)};
  pr.R = {Eigen::MatrixXd::Ones(1, 1)};
  pr.P_N = Eigen::MatrixXd::Zero(1, 1);
  pr.x0 = Eigen::VectorXd::Ones(1);
  const LqrSolution s = lqr_riccati(pr);
  const double phi = (1 + std::sqrt(5.0)) / 2;
  EXPECT_NEAR(s.P[0](0, 0), phi, 1e-12);
  EXPECT_NEAR(s.K[0](0, 0), -phi / (1 + phi), 1e-12);
  EXPECT_NEAR(s.cost, 0.5 * phi, 1e-12);  // V_0(x0) = 1/2 p x0^2
  EXPECT_LT(max_diff(lqr_dense_qp(pr).u, s.u), 1e-10);
}

TEST(LqrReference, RejectsInconsistentData) {
  LqrProblem pr = random_problem(5, 4, 2, 1);
  pr.Q.pop_back();  // 3 elements for N = 4
  EXPECT_THROW(lqr_riccati(pr), std::invalid_argument);
  pr = random_problem(5, 4, 2, 1);
  pr.S = {Eigen::MatrixXd::Zero(2, 1)};  // nx x nu instead of nu x nx
  EXPECT_THROW(lqr_dense_qp(pr), std::invalid_argument);
  pr = random_problem(5, 4, 2, 1);
  pr.R = {-100 * Eigen::MatrixXd::Identity(1, 1)};  // not convex in u
  EXPECT_THROW(lqr_riccati(pr), std::runtime_error);
  EXPECT_THROW(lqr_dense_qp(pr), std::runtime_error);
}

}  // namespace
}  // namespace arbor::test

// The IPOPT reference (ipopt_reference.hpp) against solutions known independently of IPOPT:
// HS071 (published optimum), Rosenbrock with an active bound (closed form), QPs solved in
// closed form through their KKT systems, an LQR problem (Riccati recursion, lqr_reference.hpp),
// and the multipliers' signs in every case.
#include "ipopt_reference.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>

#include "lqr_reference.hpp"

namespace arbor::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void report(const char* name, const IpoptResult& r) {
  std::printf("[ipopt] %-34s %-16s iter %3d  f evals %7ld  g evals %7ld  %.4f s\n", name,
              r.status_name.c_str(), r.iterations, r.f_evaluations, r.g_evaluations, r.seconds);
}

Eigen::Map<const Eigen::VectorXd> vec(const std::vector<double>& v) {
  return {v.data(), static_cast<Eigen::Index>(v.size())};
}

// ---- HS071 (Hock & Schittkowski no. 71, the IPOPT example) -----------------------------------
//   min x0 x3 (x0 + x1 + x2) + x2  s.t.  x0 x1 x2 x3 >= 25,  sum x_i^2 = 40,  1 <= x <= 5
Nlp hs071(bool exact) {
  Nlp nlp;
  nlp.n = 4;
  nlp.m = 2;
  nlp.f = [](const double* x) { return x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2]; };
  nlp.g = [](const double* x, double* g) {
    g[0] = x[0] * x[1] * x[2] * x[3];
    g[1] = x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3];
  };
  if (exact) {
    nlp.grad_f = [](const double* x, double* d) {
      d[0] = x[3] * (2 * x[0] + x[1] + x[2]);
      d[1] = x[0] * x[3];
      d[2] = x[0] * x[3] + 1;
      d[3] = x[0] * (x[0] + x[1] + x[2]);
    };
    nlp.jac_g = [](const double* x, double* J) {
      J[0] = x[1] * x[2] * x[3];
      J[1] = x[0] * x[2] * x[3];
      J[2] = x[0] * x[1] * x[3];
      J[3] = x[0] * x[1] * x[2];
      for (int i = 0; i < 4; ++i)
        J[4 + i] = 2 * x[i];
    };
  }
  nlp.w_l = {1, 1, 1, 1};
  nlp.w_u = {5, 5, 5, 5};
  nlp.g_l = {25, 40};
  nlp.g_u = {kInf, 40};
  nlp.w0 = {1, 5, 5, 1};
  return nlp;
}

// KKT of HS071 at IPOPT's answer with hand-written derivatives:
// grad f + J' lambda - z_l + z_u = 0.
double hs071_stationarity(const IpoptResult& r) {
  const Nlp exact = hs071(true);
  double grad[4], J[8];
  exact.grad_f(r.w.data(), grad);
  exact.jac_g(r.w.data(), J);
  double worst = 0;
  for (int i = 0; i < 4; ++i) {
    const double res =
        grad[i] + J[i] * r.lambda_g[0] + J[4 + i] * r.lambda_g[1] - r.z_l[i] + r.z_u[i];
    worst = std::max(worst, std::abs(res));
  }
  return worst;
}

void expect_hs071(const IpoptResult& r, double tol) {
  ASSERT_TRUE(r.success) << r.status_name;
  // Published optimum (Hock & Schittkowski 1981; IPOPT's hs071 example output).
  const double x_star[4] = {1.0, 4.74299963, 3.82114998, 1.37940829};
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(r.w[i], x_star[i], std::max(tol, 1e-8)) << i;
  EXPECT_NEAR(r.objective, 17.0140173, 1e-7);
  // Both constraints active: the product at its lower bound (lambda <= 0), the sphere equality.
  EXPECT_NEAR(r.g[0], 25, tol);
  EXPECT_NEAR(r.g[1], 40, tol);
  EXPECT_NEAR(r.lambda_g[0], -0.552294, 1e-6);
  EXPECT_NEAR(r.lambda_g[1], 0.161469, 1e-6);
  // x0 at its lower bound 1: z_l[0] > 0; every other bound inactive.
  EXPECT_NEAR(r.z_l[0], 1.087871, 1e-6);
  for (int i = 1; i < 4; ++i)
    EXPECT_NEAR(r.z_l[i], 0, 1e-8) << i;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(r.z_u[i], 0, 1e-8) << i;
    EXPECT_GE(r.z_l[i], 0);
    EXPECT_GE(r.z_u[i], 0);
  }
  EXPECT_LT(hs071_stationarity(r), tol);
}

TEST(IpoptReference, Hs071FiniteDifferences) {
  const IpoptResult r = solve_with_ipopt(hs071(false));
  report("hs071 fd (4-point)", r);
  expect_hs071(r, 1e-9);
}

TEST(IpoptReference, Hs071ExactDerivatives) {
  const IpoptResult r = solve_with_ipopt(hs071(true));
  report("hs071 exact", r);
  expect_hs071(r, 1e-9);
}

TEST(IpoptReference, Hs071TwoPointStencil) {
  IpoptOptions o;
  o.fd_stencil = 2;
  o.tol = 1e-9;
  const IpoptResult r = solve_with_ipopt(hs071(false), o);
  report("hs071 fd (2-point)", r);
  expect_hs071(r, 1e-7);
}

TEST(IpoptReference, Hs071LimitedMemory) {
  IpoptOptions o;
  o.exact_hessian_by_fd = false;
  o.tol = 1e-9;
  const IpoptResult r = solve_with_ipopt(hs071(false), o);
  report("hs071 fd, L-BFGS", r);
  expect_hs071(r, 1e-7);
}

// ---- Rosenbrock with x0 <= 0.5 ------------------------------------------------------------
// f = (1 - x0)^2 + 100 (x1 - x0^2)^2 >= (1 - x0)^2 >= 1/4 on x0 <= 1/2, with equality only at
// (1/2, 1/4): the unique minimiser. There df/dx0 = -2 (1 - x0) - 400 x0 (x1 - x0^2) = -1 and
// df/dx1 = 0, so stationarity grad f + z_u - z_l = 0 gives z_u[0] = 1 (or, for the bound written
// as a constraint x0 <= 0.5, lambda = +1; as -x0 >= -0.5, lambda = -1, since J = -1).
Nlp rosenbrock() {
  Nlp nlp;
  nlp.n = 2;
  nlp.f = [](const double* x) {
    return (1 - x[0]) * (1 - x[0]) + 100 * (x[1] - x[0] * x[0]) * (x[1] - x[0] * x[0]);
  };
  nlp.w0 = {-1.2, 1.0};
  return nlp;
}

TEST(IpoptReference, RosenbrockActiveBound) {
  Nlp nlp = rosenbrock();
  nlp.w_l = {-kInf, -1e20};
  nlp.w_u = {0.5, 1e20};
  const IpoptResult r = solve_with_ipopt(nlp);
  report("rosenbrock x0 <= 0.5 (bound)", r);
  ASSERT_TRUE(r.success) << r.status_name;
  EXPECT_NEAR(r.w[0], 0.5, 1e-9);
  EXPECT_NEAR(r.w[1], 0.25, 1e-9);
  EXPECT_NEAR(r.objective, 0.25, 1e-10);
  EXPECT_NEAR(r.z_u[0], 1.0, 1e-8);
  EXPECT_NEAR(r.z_u[1], 0.0, 1e-12);
  EXPECT_NEAR(r.z_l[0], 0.0, 1e-12);
  EXPECT_NEAR(r.z_l[1], 0.0, 1e-12);
}

TEST(IpoptReference, RosenbrockActiveConstraintSigns) {
  {  // x0 <= 0.5 as an upper-bounded constraint: lambda = +1
    Nlp nlp = rosenbrock();
    nlp.m = 1;
    nlp.g = [](const double* x, double* g) { g[0] = x[0]; };
    nlp.g_l = {-kInf};
    nlp.g_u = {0.5};
    const IpoptResult r = solve_with_ipopt(nlp);
    report("rosenbrock x0 <= 0.5 (g upper)", r);
    ASSERT_TRUE(r.success) << r.status_name;
    EXPECT_NEAR(r.w[0], 0.5, 1e-9);
    EXPECT_NEAR(r.w[1], 0.25, 1e-9);
    EXPECT_NEAR(r.lambda_g[0], 1.0, 1e-8);
  }
  {  // -x0 >= -0.5 as a lower-bounded constraint: lambda = -1
    Nlp nlp = rosenbrock();
    nlp.m = 1;
    nlp.g = [](const double* x, double* g) { g[0] = -x[0]; };
    nlp.g_l = {-0.5};
    nlp.g_u = {1e20};
    const IpoptResult r = solve_with_ipopt(nlp);
    report("rosenbrock -x0 >= -0.5 (g lower)", r);
    ASSERT_TRUE(r.success) << r.status_name;
    EXPECT_NEAR(r.w[0], 0.5, 1e-9);
    EXPECT_NEAR(r.w[1], 0.25, 1e-9);
    EXPECT_NEAR(r.lambda_g[0], -1.0, 1e-8);
  }
}

// ---- QPs in closed form -------------------------------------------------------------------
// Deterministic data independent of the standard library's distributions.
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

struct Qp {
  Eigen::MatrixXd H, A;
  Eigen::VectorXd c, b;
};

// min 1/2 w'Hw + c'w s.t. A w (op) b, as an Nlp (finite differences only, no derivatives given).
Nlp qp_nlp(const Qp& qp) {
  Nlp nlp;
  nlp.n = static_cast<int>(qp.H.rows());
  nlp.m = static_cast<int>(qp.A.rows());
  nlp.f = [qp](const double* w) {
    const Eigen::Map<const Eigen::VectorXd> x(w, qp.H.rows());
    return 0.5 * x.dot(qp.H * x) + qp.c.dot(x);
  };
  nlp.g = [qp](const double* w, double* g) {
    const Eigen::Map<const Eigen::VectorXd> x(w, qp.H.rows());
    Eigen::Map<Eigen::VectorXd>(g, qp.A.rows()) = qp.A * x;
  };
  return nlp;
}

// Equality-constrained QP: [H A'; A 0] [w; lambda] = [-c; b] (IPOPT's sign: grad f + A'lambda = 0).
void kkt_solve(const Qp& qp, Eigen::VectorXd& w, Eigen::VectorXd& lambda) {
  const Eigen::Index n = qp.H.rows(), m = qp.A.rows();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = qp.H;
  K.topRightCorner(n, m) = qp.A.transpose();
  K.bottomLeftCorner(m, n) = qp.A;
  Eigen::VectorXd rhs(n + m);
  rhs << -qp.c, qp.b;
  const Eigen::VectorXd sol = K.partialPivLu().solve(rhs);
  w = sol.head(n);
  lambda = sol.tail(m);
}

Qp random_qp(std::uint64_t seed, int n, int m) {
  Lcg rng{seed};
  Qp qp;
  const Eigen::MatrixXd M = rng.matrix(n, n);
  qp.H = M.transpose() * M + Eigen::MatrixXd::Identity(n, n);
  qp.A = rng.matrix(m, n);
  qp.c = rng.matrix(n, 1);
  qp.b = rng.matrix(m, 1);
  return qp;
}

TEST(IpoptReference, EqualityQpMatchesKkt) {
  const Qp qp = random_qp(7, 6, 3);
  Eigen::VectorXd w, lambda;
  kkt_solve(qp, w, lambda);
  Nlp nlp = qp_nlp(qp);
  nlp.g_l.assign(qp.b.data(), qp.b.data() + qp.b.size());
  nlp.g_u = nlp.g_l;
  const IpoptResult r = solve_with_ipopt(nlp);
  report("equality QP 6x3", r);
  ASSERT_TRUE(r.success) << r.status_name;
  EXPECT_LT((vec(r.w) - w).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((vec(r.lambda_g) - lambda).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_NEAR(r.objective, 0.5 * w.dot(qp.H * w) + qp.c.dot(w), 1e-10);
  // The multipliers are not all tiny (the comparison means something).
  EXPECT_GT(lambda.lpNorm<Eigen::Infinity>(), 0.1);
}

// Inequalities that are all active at the optimum: choose b so that the equality-constrained
// solution has lambda > 0 (A w <= b then has the same solution and multipliers), then flip the
// rows (-A w >= -b: the same w, multipliers -lambda < 0).
TEST(IpoptReference, InequalityQpSigns) {
  Qp qp = random_qp(11, 5, 2);
  // Unconstrained minimiser w_u = -H^{-1} c; put b below A w_u so that both rows push back.
  const Eigen::VectorXd w_free = qp.H.ldlt().solve(-qp.c);
  qp.b = qp.A * w_free - Eigen::VectorXd::Constant(2, 0.5);
  Eigen::VectorXd w, lambda;
  kkt_solve(qp, w, lambda);
  ASSERT_GT(lambda.minCoeff(), 0.01) << "test data: the rows must be strictly active";

  Nlp upper = qp_nlp(qp);
  upper.g_l = {-kInf, -kInf};
  upper.g_u = {qp.b(0), qp.b(1)};
  const IpoptResult ru = solve_with_ipopt(upper);
  report("QP A w <= b (active)", ru);
  ASSERT_TRUE(ru.success) << ru.status_name;
  EXPECT_LT((vec(ru.w) - w).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((vec(ru.lambda_g) - lambda).lpNorm<Eigen::Infinity>(), 1e-8);

  Qp flipped = qp;
  flipped.A = -qp.A;
  Nlp lower = qp_nlp(flipped);
  lower.g_l = {-qp.b(0), -qp.b(1)};
  lower.g_u = {kInf, kInf};
  const IpoptResult rl = solve_with_ipopt(lower);
  report("QP -A w >= -b (active)", rl);
  ASSERT_TRUE(rl.success) << rl.status_name;
  EXPECT_LT((vec(rl.w) - w).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((vec(rl.lambda_g) + lambda).lpNorm<Eigen::Infinity>(), 1e-8);
}

// min 1/2 |w - c|^2 s.t. -1 <= w <= 1: w = clamp(c), z_l = max(-1 - c, 0), z_u = max(c - 1, 0).
TEST(IpoptReference, BoxProjectionBoundMultipliers) {
  const std::vector<double> c = {-3.0, -0.25, 0.5, 2.5};
  Nlp nlp;
  nlp.n = 4;
  nlp.f = [c](const double* w) {
    double s = 0;
    for (int i = 0; i < 4; ++i)
      s += 0.5 * (w[i] - c[i]) * (w[i] - c[i]);
    return s;
  };
  nlp.w_l.assign(4, -1.0);
  nlp.w_u.assign(4, 1.0);
  const IpoptResult r = solve_with_ipopt(nlp);
  report("box projection", r);
  ASSERT_TRUE(r.success) << r.status_name;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(r.w[i], std::clamp(c[i], -1.0, 1.0), 1e-9) << i;
    EXPECT_NEAR(r.z_l[i], std::max(-1.0 - c[i], 0.0), 1e-8) << i;
    EXPECT_NEAR(r.z_u[i], std::max(c[i] - 1.0, 0.0), 1e-8) << i;
  }
}

// ---- an LQR problem as a simultaneous NLP -------------------------------------------------
// Variables (x_0 u_0 x_1 u_1 ... x_N), constraints x_0 = x0 and x_{k+1} - A x_k - B u_k - b = 0.
// The optimum is Riccati's; the multiplier of dyn_k is minus the gradient of the cost-to-go,
// lambda_k = -(P_{k+1} x_{k+1} + p_{k+1}) (stationarity in x_{k+1}).
TEST(IpoptReference, LqrAsNlpMatchesRiccati) {
  LqrProblem pr;
  pr.N = 6;
  const double dt = 0.1;
  pr.A = {(Eigen::MatrixXd(2, 2) << 1, dt, 0, 1).finished()};
  pr.B = {(Eigen::MatrixXd(2, 1) << 0.5 * dt * dt, dt).finished()};
  pr.b = {(Eigen::VectorXd(2) << 0.0, -0.05).finished()};  // gravity-like drift
  pr.Q = {Eigen::MatrixXd::Identity(2, 2)};
  pr.R = {Eigen::MatrixXd::Constant(1, 1, 0.1)};
  pr.S = {(Eigen::MatrixXd(1, 2) << 0.02, 0.01).finished()};
  pr.q = {(Eigen::VectorXd(2) << -0.3, 0.0).finished()};
  pr.P_N = 10 * Eigen::MatrixXd::Identity(2, 2);
  pr.p_N = (Eigen::VectorXd(2) << -3.0, 0.0).finished();
  pr.x0 = (Eigen::VectorXd(2) << 1.0, -0.5).finished();
  const LqrSolution ref = lqr_riccati(pr);

  const int nx = 2, nu = 1, N = pr.N, nz = nx + nu;
  auto xi = [&](int k) { return k * nz; };
  auto ui = [&](int k) { return k * nz + nx; };
  Nlp nlp;
  nlp.n = N * nz + nx;
  nlp.m = (N + 1) * nx;
  nlp.f = [&](const double* w) {
    std::vector<Eigen::VectorXd> x(N + 1), u(N);
    for (int k = 0; k <= N; ++k)
      x[k] = Eigen::Map<const Eigen::VectorXd>(w + xi(k), nx);
    for (int k = 0; k < N; ++k)
      u[k] = Eigen::Map<const Eigen::VectorXd>(w + ui(k), nu);
    return lqr_cost(pr, x, u);
  };
  nlp.g = [&](const double* w, double* g) {
    Eigen::Map<Eigen::VectorXd>(g, nx) = Eigen::Map<const Eigen::VectorXd>(w, nx) - pr.x0;
    for (int k = 0; k < N; ++k) {
      const Eigen::Map<const Eigen::VectorXd> x(w + xi(k), nx), u(w + ui(k), nu),
          x1(w + xi(k + 1), nx);
      Eigen::Map<Eigen::VectorXd>(g + (k + 1) * nx, nx) =
          x1 - pr.A_at(k) * x - pr.B_at(k) * u - pr.b_at(k);
    }
  };
  nlp.g_l.assign(nlp.m, 0.0);
  nlp.g_u.assign(nlp.m, 0.0);
  const IpoptResult r = solve_with_ipopt(nlp);
  report("LQR N=6 simultaneous", r);
  ASSERT_TRUE(r.success) << r.status_name;
  for (int k = 0; k <= N; ++k) {
    EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(r.w.data() + xi(k), nx) - ref.x[k])
                  .lpNorm<Eigen::Infinity>(),
              1e-8)
        << "x_" << k;
  }
  for (int k = 0; k < N; ++k) {
    EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(r.w.data() + ui(k), nu) - ref.u[k])
                  .lpNorm<Eigen::Infinity>(),
              1e-8)
        << "u_" << k;
    const Eigen::VectorXd costate = ref.P[k + 1] * ref.x[k + 1] + ref.p[k + 1];
    EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(r.lambda_g.data() + (k + 1) * nx, nx) + costate)
                  .lpNorm<Eigen::Infinity>(),
              1e-7)
        << "lambda of dyn_" << k;
  }
  EXPECT_NEAR(r.objective, ref.cost, 1e-9);
}

// ---- failures come back as failures -------------------------------------------------------
TEST(IpoptReference, InfeasibleProblemIsReported) {
  Nlp nlp;  // x^2 + y^2 <= 1 and x + y >= 3: no point satisfies both
  nlp.n = 2;
  nlp.m = 2;
  nlp.f = [](const double* w) { return w[0] + w[1]; };
  nlp.g = [](const double* w, double* g) {
    g[0] = w[0] * w[0] + w[1] * w[1];
    g[1] = w[0] + w[1];
  };
  nlp.g_l = {-kInf, 3};
  nlp.g_u = {1, kInf};
  const IpoptResult r = solve_with_ipopt(nlp);
  report("infeasible", r);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.status, 2) << r.status_name;  // Infeasible_Problem_Detected
}

TEST(IpoptReference, InvalidInputAndCallbackErrorsThrow) {
  Nlp nlp = rosenbrock();
  nlp.w_l = {0.0};  // wrong size
  EXPECT_THROW(solve_with_ipopt(nlp), std::invalid_argument);
  nlp = rosenbrock();
  nlp.m = 1;  // g missing
  EXPECT_THROW(solve_with_ipopt(nlp), std::invalid_argument);
  nlp = rosenbrock();
  IpoptOptions bad;
  bad.string_options = {{"no_such_option", "x"}};
  EXPECT_THROW(solve_with_ipopt(nlp, bad), std::invalid_argument);
  nlp.f = [](const double*) -> double { throw std::runtime_error("from f"); };
  EXPECT_THROW(solve_with_ipopt(nlp), std::runtime_error);
}

}  // namespace
}  // namespace arbor::test

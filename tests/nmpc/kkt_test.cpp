// nmpc::kkt_residuals (include/arbor/nmpc/kkt.hpp), the KKT residuals the controller records at
// every linearisation, against a plain dense computation written here on the QP assembled by the
// QP tests' reference (tests/qp/qp_reference.hpp, to_ref: stacked variables, dynamics rows
// [-A -B I] = b, general rows): stationarity |g + A' lam_a + lam_x|_inf, primal max(0, lb, -ub)
// over every bound and row at d = 0 (|b| for the dynamics rows), complementarity |lam * bound|
// for the bound the multiplier's sign names (infinite for an absent one), equalities and zero
// multipliers excluded. Random data at odd sizes, with infinite, equal and violated bounds and
// multipliers of both signs and zero; double and float.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "arbor/nmpc/kkt.hpp"
#include "arbor_test.hpp"
#include "qp_reference.hpp"

namespace {
namespace qt = arbor::qp::test;

struct Reference {
  double stationarity = 0, primal = 0, complementarity = 0;
};

/// The bound pair of one constraint, the multiplier's complementarity term, plainly.
void add_bound(double lb, double ub, double lam, Reference& r) {
  r.primal = std::max({r.primal, lb, -ub});
  if (lam == 0 || lb == ub)
    return;
  const double bound = lam > 0 ? ub : lb;
  r.complementarity =
      std::max(r.complementarity,
               std::isinf(bound) ? std::numeric_limits<double>::infinity() : std::abs(lam * bound));
}

Reference plain_kkt(const qt::RefQp& q, const Eigen::VectorXd& lx, const Eigen::VectorXd& la) {
  Reference r;
  r.stationarity = (q.g + q.A.transpose() * la + lx).cwiseAbs().maxCoeff();
  for (int i = 0; i < q.lbx.size(); ++i)
    add_bound(q.lbx[i], q.ubx[i], lx[i], r);
  for (int i = 0; i < q.lba.size(); ++i)
    add_bound(q.lba[i], q.uba[i], la[i], r);
  return r;
}

/// One bound pair in delta form: both finite around 0, one side absent, an equality, or violated.
template <class T>
void random_bounds(std::mt19937& rng, T& lb, T& ub) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::uniform_real_distribution<double> u(0.0, 2.0);
  const double a = u(rng), b = u(rng);
  switch (std::uniform_int_distribution<int>(0, 5)(rng)) {
    case 0:
      lb = -a, ub = inf;
      break;
    case 1:
      lb = -inf, ub = b;
      break;
    case 2:
      lb = ub = a - 1;  // an equality
      break;
    case 3:
      lb = a, ub = a + b;  // violated from below
      break;
    case 4:
      lb = -inf, ub = inf;
      break;
    default:
      lb = -a, ub = b;
  }
}

template <class Vec>
void random_multipliers(std::mt19937& rng, Vec& lam) {
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int i = 0; i < lam.size(); ++i)
    lam[i] = std::uniform_int_distribution<int>(0, 2)(rng) == 0 ? 0.0 : u(rng);
}

/// Fills every matrix and vector of qp with fill(m) and every bound pair with bounds(lb, ub).
template <class Qp, class Fill, class Bounds>
void fill_qp(Qp& qp, const Fill& fill, const Bounds& bounds) {
  for (auto& s : qp.stage) {
    fill(s.Q), fill(s.S), fill(s.R), fill(s.q), fill(s.r), fill(s.A), fill(s.B), fill(s.b);
    fill(s.C), fill(s.D);
    bounds(s.lbx, s.ubx), bounds(s.lbu, s.ubu), bounds(s.lg, s.ug);
  }
  fill(qp.terminal.Q), fill(qp.terminal.q), fill(qp.terminal.C);
  bounds(qp.terminal.lbx, qp.terminal.ubx), bounds(qp.terminal.lg, qp.terminal.ug);
}

template <class T, int N, int NX, int NU, int NG, int NGN>
void check(unsigned seed) {
  using Qp = arbor::qp::OcpQp<T, N, NX, NU, NG, NGN>;
  SCOPED_TRACE(::testing::Message() << "N " << N << " nx " << NX << " nu " << NU << " ng " << NG
                                    << " ngn " << NGN << " seed " << seed);
  static Qp qp;
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const auto fill = [&](auto& m) {
    for (int i = 0; i < m.size(); ++i)
      m.data()[i] = T(g(rng));
  };
  const auto bounds = [&](auto& lb, auto& ub) {
    for (int i = 0; i < lb.size(); ++i)
      random_bounds(rng, lb[i], ub[i]);
  };
  fill_qp(qp, fill, bounds);
  Eigen::Matrix<T, Qp::nv, 1> lx;
  Eigen::Matrix<T, Qp::na, 1> la;
  random_multipliers(rng, lx);
  random_multipliers(rng, la);

  arbor::nmpc::KktResiduals<T> r;
  {
    arbor::test::NoAllocScope guard;
    r = arbor::nmpc::kkt_residuals(qp, lx, la);
  }
  const Reference ref =
      plain_kkt(qt::to_ref(qp), lx.template cast<double>(), la.template cast<double>());
  const double tol = std::is_same_v<T, float> ? 1e-5 : 1e-13;
  EXPECT_NEAR(double(r.stationarity), ref.stationarity, tol * (1 + ref.stationarity));
  EXPECT_NEAR(double(r.primal), ref.primal, tol * (1 + ref.primal));
  if (std::isinf(ref.complementarity)) {
    EXPECT_TRUE(std::isinf(double(r.complementarity))) << r.complementarity;
  } else {
    EXPECT_NEAR(double(r.complementarity), ref.complementarity, tol * (1 + ref.complementarity));
  }
}

TEST(NmpcKkt, ResidualsMatchAPlainDenseComputation) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    check<double, 5, 3, 2, 1, 2>(seed);
    check<double, 1, 1, 1, 0, 0>(seed);
    check<double, 7, 13, 3, 2, 0>(seed);
    check<float, 4, 7, 1, 0, 1>(seed);
  }
}

// Every multiplier on a finite bound (no absent one): a finite complementarity, compared to the
// digit (the case above is mostly infinite: most draws name some absent bound).
TEST(NmpcKkt, FiniteComplementarityMatches) {
  using Qp = arbor::qp::OcpQp<double, 3, 2, 1, 1, 1>;
  static Qp qp;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto fill = [&](auto& m) {
    for (int i = 0; i < m.size(); ++i)
      m.data()[i] = u(rng);
  };
  const auto bounds = [&](auto& lb, auto& ub) {
    for (int i = 0; i < lb.size(); ++i)
      lb[i] = u(rng) - 1.5, ub[i] = u(rng) + 1.5;
  };
  fill_qp(qp, fill, bounds);
  qp.stage[1].lbx[0] = 0.25;  // violated: primal residual 0.25
  Eigen::Matrix<double, Qp::nv, 1> lx;
  Eigen::Matrix<double, Qp::na, 1> la;
  random_multipliers(rng, lx);
  random_multipliers(rng, la);
  const auto r = arbor::nmpc::kkt_residuals(qp, lx, la);
  const Reference ref = plain_kkt(qt::to_ref(qp), lx, la);
  EXPECT_GT(ref.complementarity, 0.0);
  EXPECT_TRUE(std::isfinite(ref.complementarity));
  EXPECT_NEAR(r.complementarity, ref.complementarity, 1e-14 * (1 + ref.complementarity));
  EXPECT_GE(ref.primal, 0.25);
  EXPECT_NEAR(r.primal, ref.primal, 1e-15);
  EXPECT_NEAR(r.stationarity, ref.stationarity, 1e-13 * (1 + ref.stationarity));
  // a NaN variable bound (the user's bounds are not checked before the residuals are recorded)
  // under a nonzero multiplier: infinite complementarity, as for an absent bound
  qp.stage[0].ubx[0] = std::numeric_limits<double>::quiet_NaN();
  lx[0] = 1.0;
  EXPECT_TRUE(std::isinf(arbor::nmpc::kkt_residuals(qp, lx, la).complementarity));
}
}  // namespace

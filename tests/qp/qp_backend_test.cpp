// The OCP solver's linear algebra against a dense reference. The exact-dynamics Riccati backend
// solves the KKT system [M_P D' E_B'; D 0 0; E_B 0 0] (M = H + delta I + A_W' E A_W assembled
// densely here with dynamic Eigen from the definition in active_set.hpp, without the weights of
// the dynamics rows D and of the working bounds of the inputs and of x_0, E_B, which it holds
// exactly by fixing the variable; backend.hpp, ExactRowBackend): checked against that dense KKT
// matrix solved by Eigen's LU (primal step, dynamics multipliers and fixed-bound multipliers)
// after a full factorization and through sequences of working-set changes applied through
// mark_changed() (rank-one updates, downdates, column deletions and insertions, and their
// refactorization fallback). (The penalised backends retired in issue 38 were checked here against
// M^-1 b.)
// Every backend call runs inside an allocation guard.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <array>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/qp/ocp_riccati_backend.hpp"
#include "qp_reference.hpp"

namespace {
using arbor::qp::OcpQp;
using arbor::qp::detail::ConstraintState;
namespace t = arbor::qp::test;

/// True for the dynamics rows of Qp (flat row index j).
template <typename Qp>
bool is_dynamics_row(int j) {
  constexpr int NR = Qp::nx + Qp::ng;
  return j < Qp::horizon * NR && j % NR < Qp::nx;
}

/// The bounds the Riccati backend holds exactly: those of u_k (k < N) and of x_0 (flat index i),
/// written from the problem layout (problem.hpp), not from the backend.
template <typename Qp>
bool is_exact_bound(int i) {
  constexpr int NW = Qp::nx + Qp::nu;
  return i < Qp::horizon * NW && (i < Qp::nx || i % NW >= Qp::nx);
}

/// M = H + delta I + A_W' E A_W; without the dynamics rows and the exact bounds when exact (the
/// Riccati backend).
template <typename Qp>
Eigen::MatrixXd dense_m(const t::RefQp& r, const ConstraintState* ws, double delta, double w,
                        const Eigen::VectorXd& wa, bool exact = false) {
  const int nv = Qp::nv, na = Qp::na;
  Eigen::MatrixXd m = r.H;
  m.diagonal().array() += delta;
  for (int i = 0; i < nv; ++i) {
    if (ws[i] != ConstraintState::inactive && !(exact && is_exact_bound<Qp>(i)))
      m(i, i) += w;
  }
  for (int j = 0; j < na; ++j) {
    if (ws[nv + j] != ConstraintState::inactive && !(exact && is_dynamics_row<Qp>(j)))
      m += wa(j) * r.A.row(j).transpose() * r.A.row(j);
  }
  return m;
}

template <typename Qp, typename Backend>
void check_backend(unsigned seed0, int count) {
  constexpr int nv = Qp::nv, na = Qp::na, N = Qp::horizon, NX = Qp::nx, NG = Qp::ng;
  static Qp qp;
  static Backend be;
  static std::array<ConstraintState, nv + na> ws{};
  t::RandomOcpOptions opt;
  for (int c = 0; c < count; ++c) {
    std::mt19937 rng(seed0 + static_cast<unsigned>(c));
    t::random_ocp(qp, rng, opt);
    const t::RefQp ref = t::to_ref(qp);
    std::uniform_int_distribution<int> coin(0, 2);
    for (int i = 0; i < nv + na; ++i)
      ws[i] = coin(rng) == 0 ? ConstraintState::upper : ConstraintState::inactive;
    for (int k = 0; k < N; ++k) {  // dynamics rows are equalities
      for (int i = 0; i < NX; ++i)
        ws[nv + k * (NX + NG) + i] = ConstraintState::equality;
    }
    const double delta = 1e-8, w = 1e6;
    Eigen::Matrix<double, na, 1> wa;
    Eigen::Matrix<double, nv, 1> b, x;
    int done = 0;
    be.p = &qp;
    {
      arbor::test::NoAllocScope guard;
      be.row_norms_sq(wa);
    }
    for (int j = 0; j < na; ++j)
      wa(j) = wa(j) > 0 ? w / wa(j) : w;
    {
      arbor::test::NoAllocScope guard;
      be.mark_all();
      done = be.factorize(ws.data(), delta, w, wa);
    }
    SCOPED_TRACE(::testing::Message() << "seed " << seed0 + c);
    ASSERT_EQ(done, N + 1);
    std::uniform_int_distribution<int> pick(0, nv + na - 1);
    std::normal_distribution<double> nd(0.0, 1.0);
    for (int round = 0; round < 12; ++round) {
      static_assert(arbor::qp::detail::ExactRowBackend<Backend, double, nv, na>);
      const Eigen::MatrixXd m = dense_m<Qp>(ref, ws.data(), delta, w, wa, true);
      for (int i = 0; i < nv; ++i)
        b(i) = nd(rng);
      x = b;
      {
        // [M D' E'; D 0 0; E 0 0] [x; nu; lam_B] = [b; e; c] with D the dynamics rows of A
        // and E the rows of I of the working exact bounds
        int nb_rows = 0;
        for (int i = 0; i < nv; ++i)
          nb_rows += ws[i] != ConstraintState::inactive && is_exact_bound<Qp>(i) ? 1 : 0;
        const int nd_rows = N * NX + nb_rows;
        Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(nv + nd_rows, nv + nd_rows);
        Eigen::VectorXd rhs(nv + nd_rows);
        Eigen::Matrix<double, na, 1> e;
        Eigen::Matrix<double, nv, 1> cb;
        e.setZero();
        cb.setZero();
        kkt.topLeftCorner(nv, nv) = m;
        rhs.head(nv) = b;
        int c = 0;
        for (int j = 0; j < na; ++j) {
          if (!is_dynamics_row<Qp>(j))
            continue;
          e(j) = nd(rng);
          kkt.block(nv + c, 0, 1, nv) = ref.A.row(j);
          kkt.block(0, nv + c, nv, 1) = ref.A.row(j).transpose();
          rhs(nv + c) = e(j);
          ++c;
        }
        for (int i = 0; i < nv; ++i) {
          if (ws[i] == ConstraintState::inactive || !is_exact_bound<Qp>(i))
            continue;
          cb(i) = nd(rng);
          kkt(nv + c, i) = 1;
          kkt(i, nv + c) = 1;
          rhs(nv + c) = cb(i);
          ++c;
        }
        const Eigen::VectorXd sol = kkt.fullPivLu().solve(rhs);
        {
          arbor::test::NoAllocScope guard;
          be.solve_exact(x, e, cb, wa);
        }
        Eigen::VectorXd got(nv + nd_rows);
        got.head(nv) = x;
        c = 0;
        for (int j = 0; j < na; ++j) {
          if (is_dynamics_row<Qp>(j))
            got(nv + c++) = e(j);
        }
        for (int i = 0; i < nv; ++i) {
          if (ws[i] != ConstraintState::inactive && is_exact_bound<Qp>(i))
            got(nv + c++) = cb(i);
        }
        const double res = (kkt * got - rhs).cwiseAbs().maxCoeff();
        EXPECT_LE(res, 1e-12 * (1 + kkt.cwiseAbs().maxCoeff() * sol.cwiseAbs().maxCoeff()))
            << "round " << round << " error " << (got - sol).cwiseAbs().maxCoeff();
      }
      // 1-3 working-set changes (adds, drops, side switches) between the solves
      const int changes = 1 + round % 3;
      for (int ch = 0; ch < changes; ++ch) {
        int i = pick(rng);
        if (ws[i] == ConstraintState::equality)
          continue;
        ws[i] =
            ws[i] == ConstraintState::inactive
                ? (coin(rng) == 0 ? ConstraintState::lower : ConstraintState::upper)
                : (coin(rng) == 0 ? ConstraintState::inactive
                                  : (ws[i] == ConstraintState::upper ? ConstraintState::lower
                                                                     : ConstraintState::inactive));
        arbor::test::NoAllocScope guard;
        be.mark_changed(i);
      }
      {
        arbor::test::NoAllocScope guard;
        done = be.factorize(ws.data(), delta, w, wa);
      }
      ASSERT_GE(done, 0);
    }
  }
}

using Small = OcpQp<double, 5, 3, 2, 2, 1>;
using NoInput = OcpQp<double, 4, 2, 0, 1, 0>;
using Wide = OcpQp<double, 6, 4, 3, 0, 2>;
// sizes that fill the 4 x 4 blocks of the kernels (kernels.hpp) and leave tails of 1 and 3
using Blocked = OcpQp<double, 4, 9, 6, 2, 1>;
template <typename Qp>
using Riccati =
    arbor::qp::detail::OcpRiccatiBackend<double, Qp::horizon, Qp::nx, Qp::nu, Qp::ng, Qp::ngn>;

TEST(QpBackend, RiccatiMatchesDenseKktThroughUpdates) {
  check_backend<Small, Riccati<Small>>(100, 20);
  check_backend<NoInput, Riccati<NoInput>>(200, 20);
  check_backend<Wide, Riccati<Wide>>(300, 20);
  check_backend<Blocked, Riccati<Blocked>>(400, 20);
}

/// The Riccati backend updates: a change in the last path stage sweeps the stages before it
/// by rank-one updates instead of refactorizing them.
TEST(QpBackend, RiccatiWorkingSetChangeIsAnUpdate) {
  using Qp = Small;
  static Qp qp;
  static Riccati<Qp> be;
  static std::array<ConstraintState, Qp::nv + Qp::na> ws{};
  std::mt19937 rng(7);
  t::random_ocp(qp, rng, t::RandomOcpOptions{});
  for (auto& s : ws)
    s = ConstraintState::inactive;
  Eigen::Matrix<double, Qp::na, 1> wa;
  be.p = &qp;
  be.row_norms_sq(wa);
  for (int j = 0; j < Qp::na; ++j)
    wa(j) = 1e6 / wa(j);
  be.mark_all();
  ASSERT_EQ(be.factorize(ws.data(), 1e-8, 1e6, wa), Qp::horizon + 1);
  const int i = Qp::state_offset(Qp::horizon - 1) + 1;  // a bound of x_{N-1}
  ws[i] = ConstraintState::upper;
  be.mark_changed(i);
  EXPECT_EQ(be.factorize(ws.data(), 1e-8, 1e6, wa), 0);
  EXPECT_EQ(be.updates_last, 1);
  ws[i] = ConstraintState::inactive;  // and removed again: a downdate
  be.mark_changed(i);
  EXPECT_EQ(be.factorize(ws.data(), 1e-8, 1e6, wa), 0);
  EXPECT_EQ(be.updates_last, 1);
  // a bound of u_{N-1}, held exactly: fixing the input deletes its column, freeing it inserts
  // the column again; both are sweeps, not refactorizations
  const int iu = Qp::input_offset(Qp::horizon - 1);
  ws[iu] = ConstraintState::lower;
  be.mark_changed(iu);
  EXPECT_EQ(be.factorize(ws.data(), 1e-8, 1e6, wa), 0);
  EXPECT_EQ(be.updates_last, 1);
  ws[iu] = ConstraintState::inactive;
  be.mark_changed(iu);
  EXPECT_EQ(be.factorize(ws.data(), 1e-8, 1e6, wa), 0);
  EXPECT_EQ(be.updates_last, 1);
}

}  // namespace

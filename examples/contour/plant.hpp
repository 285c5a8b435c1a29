// The simulated plants of the contour example. `Plant` is what the closed loop needs of one (a
// concept; PlantRef holds any of them, chosen once): arbor's, here, and MuJoCo's
// (mujoco_plant.hpp, the demo's default) satisfy it. ArborPlant integrates the Gen3 with arbor's
// own forward dynamics (aba) by RK4 at 1 ms, 20 substeps per 0.02 s sample (20 aba calls x 4 per
// sample), applying the controller's first input; s and sd (virtual states) integrate the applied
// sdd exactly (`--plant arbor`).
//   OCP-FD: the torque tau of u_0 is held over the sample (or, with a TorqueLaw, the law's
//           torque at each substep: the torque-rate inner loop).
//   OCP-ID: an inner 1 kHz computed-torque loop: at each 1 ms substep tau = rnea(q, qd, qdd_cmd)
//           on the controller's (nominal) model, held over the substep; the plant moves with its
//           own model, so with a model mismatch the acceleration differs from the command.
// Model mismatch (option): the plant's bracelet link carries a point mass at the end-effector
// frame (PayloadRobot); the controller keeps the nominal model.
#pragma once

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <cstddef>

#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"
#include "task.hpp"

namespace contour {

/// The plants' default substep hook: nothing.
struct NoSubstepHook {
  template <class Q, class V, class T>
  void operator()(const Q&, const V&, const T&) const {}
};

/// A substep hook that calls fn(obj, q, qd, tau) (nothing when fn is null): what PlantRef passes
/// to a plant's step().
struct SubstepHook {
  using Vq = VecN<double, nq>;
  void* obj = nullptr;
  void (*fn)(void*, const Vq&, const Vq&, const Vq&) = nullptr;
  void operator()(const Vq& q, const Vq& qd, const Vq& tau) const {
    if (fn)
      fn(obj, q, qd, tau);
  }
};

/// A torque law a plant calls before each substep k (0-based within the sample) of an OCP-FD
/// sample with the torque it would apply (u_0's), which the law may change: a torque-rate inner
/// loop (ContourLoop with Options::inner_loop). Nothing when fn is null.
struct TorqueLaw {
  using Vq = VecN<double, nq>;
  void* obj = nullptr;
  void (*fn)(void*, int, Vq&) = nullptr;
  void operator()(int k, Vq& tau) const {
    if (fn)
      fn(obj, k, tau);
  }
};

/// What the closed loop needs of a plant: the state x = [q, qd, s, sd]; step(form, u, hook), one
/// sample of length h from u = [tau, sdd] (fd) or [qdd_cmd, sdd] (id, a computed-torque loop on
/// `nominal`, the controller's model), calling hook(q, qd, tau) after each substep (of length
/// substep_dt()); the torque of the last substep and the largest over the sample; the end
/// effector's position and rotation error (task.hpp's rotation_error) at x.
template <class P>
concept Plant = requires(P& p, const Reference& ref, const VecN<double, nu>& u) {
  { p.x } -> std::convertible_to<VecN<double, nx>>;
  { p.tau_applied } -> std::convertible_to<VecN<double, nq>>;
  { p.tau_peak } -> std::convertible_to<VecN<double, nq>>;
  { p.nominal } -> std::convertible_to<arbor::Data<Robot, double>&>;
  p.step(Formulation::fd, u, SubstepHook{}, TorqueLaw{});
  { p.ee_position() } -> std::convertible_to<VecN<double, 3>>;
  { p.rotation_error(ref) } -> std::convertible_to<VecN<double, 3>>;
  { p.substep_dt() } -> std::convertible_to<double>;
};

namespace detail {
/// The inertia of body b of R with a point mass m at point c (body frame) added.
constexpr arbor::model::Inertia with_point_mass(const arbor::model::Inertia& in, double m,
                                                const double (&c)[3]) {
  arbor::model::Inertia out = in;
  const double M = in.mass + m;
  double com[3]{};
  for (int i = 0; i < 3; ++i)
    com[i] = (in.mass * in.com[i] + m * c[i]) / M;
  // parallel-axis terms of both parts about the new centre of mass
  const auto add = [&out](double mass, const double(&d)[3]) {
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        out.I[i][j] += mass * ((i == j ? dd : 0.0) - d[i] * d[j]);
  };
  const double d1[3]{in.com[0] - com[0], in.com[1] - com[1], in.com[2] - com[2]};
  const double d2[3]{c[0] - com[0], c[1] - com[1], c[2] - com[2]};
  add(in.mass, d1);
  add(m, d2);
  out.mass = M;
  for (int i = 0; i < 3; ++i)
    out.com[i] = com[i];
  return out;
}
}  // namespace detail

/// The Gen3 with a 0.5 kg point mass at the end-effector frame (on the bracelet link's body).
struct PayloadRobot : Robot {
  static constexpr double payload = 0.5;  ///< [kg]
  static constexpr std::array<arbor::model::Inertia, nb> body_inertia = [] {
    std::array<arbor::model::Inertia, nb> b = Robot::body_inertia;
    constexpr auto& f = Robot::frames[std::size_t(ee_frame)];
    const double c[3]{f.placement.p[0], f.placement.p[1], f.placement.p[2]};
    b[std::size_t(f.body)] = detail::with_point_mass(b[std::size_t(f.body)], payload, c);
    return b;
  }();
};

/// arbor's plant: state [q, qd, s, sd], model PR (Robot or PayloadRobot).
template <class PR>
struct ArborPlant {
  using Vx = VecN<double, nx>;
  using Vq = VecN<double, nq>;
  static constexpr int substeps = 20;
  static constexpr double dt = h / substeps;  // 1 ms

  Vx x = Vx::Zero();
  arbor::Data<PR, double> d;           ///< the plant's dynamics workspace
  arbor::Data<Robot, double> nominal;  ///< the nominal model (computed torque of OCP-ID)
  Vq tau_applied = Vq::Zero();         ///< the torque of the last substep
  Vq tau_peak = Vq::Zero();            ///< max |tau| over the last sample's substeps

  /// One sample of length h: u = [tau, sdd] (fd) or [qdd_cmd, sdd] (id); after each substep
  /// hook(q, qd, tau) with the state it reached and the torque it applied (a torque loop's
  /// observer runs there).
  template <class Hook = NoSubstepHook>
  void step(Formulation form, const VecN<double, nu>& u, Hook&& hook = {}, TorqueLaw law = {}) {
    tau_peak.setZero();
    for (int k = 0; k < substeps; ++k) {
      Vq tau;
      if (form == Formulation::fd) {
        tau = u.head<nq>();
        law(k, tau);
      } else {
        tau =
            arbor::rnea<Robot>(nominal, Vq(x.head<nq>()), Vq(x.segment<nq>(nq)), Vq(u.head<nq>()));
      }
      tau_applied = tau;
      tau_peak = tau_peak.cwiseMax(tau.cwiseAbs());
      rk4(tau);
      hook(Vq(x.head<nq>()), Vq(x.segment<nq>(nq)), tau);
    }
    // s, sd: sdd constant over the sample (exact)
    const double sdd = u[7];
    x[14] += h * x[15] + 0.5 * h * h * sdd;
    x[15] += h * sdd;
  }

  /// The substep [s].
  static constexpr double substep_dt() { return dt; }

  /// End-effector position at the plant's q.
  VecN<double, 3> ee_position() {
    arbor::forward_kinematics<PR>(d, Vq(x.head<nq>()));
    return arbor::frame_placement<PR>(d, ee_frame).p;
  }
  /// End-effector rotation error against the reference.
  VecN<double, 3> rotation_error(const Reference& ref) {
    arbor::forward_kinematics<PR>(d, Vq(x.head<nq>()));
    return contour::rotation_error<double>(ref, arbor::frame_placement<PR>(d, ee_frame).R);
  }

 private:
  VecN<double, 2 * nq> f(const VecN<double, 2 * nq>& y, const Vq& tau) {
    VecN<double, 2 * nq> r;
    r.head<nq>() = y.tail<nq>();
    r.tail<nq>() = arbor::aba<PR>(d, Vq(y.head<nq>()), Vq(y.tail<nq>()), tau);
    return r;
  }
  void rk4(const Vq& tau) {
    const VecN<double, 2 * nq> y = x.head<2 * nq>();
    const auto k1 = f(y, tau);
    const auto k2 = f(y + 0.5 * dt * k1, tau);
    const auto k3 = f(y + 0.5 * dt * k2, tau);
    const auto k4 = f(y + dt * k3, tau);
    x.head<2 * nq>() = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
};
static_assert(Plant<ArborPlant<Robot>> && Plant<ArborPlant<PayloadRobot>>);

/// Any Plant, by reference (not owned): the closed loop's plant, chosen once.
class PlantRef {
 public:
  using Vx = VecN<double, nx>;
  using Vq = VecN<double, nq>;

  template <Plant P>
  explicit PlantRef(P& p)
      : obj_(&p),
        x_(&p.x),
        tau_applied_(&p.tau_applied),
        tau_peak_(&p.tau_peak),
        nominal_(&p.nominal),
        substep_dt_(p.substep_dt()),
        step_([](void* o, Formulation f, const VecN<double, nu>& u, SubstepHook hook,
                 TorqueLaw law) { static_cast<P*>(o)->step(f, u, hook, law); }),
        ee_position_([](void* o) { return VecN<double, 3>(static_cast<P*>(o)->ee_position()); }),
        rotation_error_([](void* o, const Reference& r) {
          return VecN<double, 3>(static_cast<P*>(o)->rotation_error(r));
        }) {}

  Vx& x() { return *x_; }
  const Vx& x() const { return *x_; }
  const Vq& tau_applied() const { return *tau_applied_; }
  const Vq& tau_peak() const { return *tau_peak_; }
  arbor::Data<Robot, double>& nominal() { return *nominal_; }
  double substep_dt() const { return substep_dt_; }
  void step(Formulation f, const VecN<double, nu>& u, SubstepHook hook = {}, TorqueLaw law = {}) {
    step_(obj_, f, u, hook, law);
  }
  VecN<double, 3> ee_position() { return ee_position_(obj_); }
  VecN<double, 3> rotation_error(const Reference& r) { return rotation_error_(obj_, r); }

 private:
  void* obj_;
  Vx* x_;
  Vq* tau_applied_;
  Vq* tau_peak_;
  arbor::Data<Robot, double>* nominal_;
  double substep_dt_;
  void (*step_)(void*, Formulation, const VecN<double, nu>&, SubstepHook, TorqueLaw);
  VecN<double, 3> (*ee_position_)(void*);
  VecN<double, 3> (*rotation_error_)(void*, const Reference&);
};

}  // namespace contour

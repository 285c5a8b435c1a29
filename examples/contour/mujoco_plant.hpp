// The contour example's independent plant: MuJoCo (Debian's libmujoco-dev) simulating the Gen3
// from the same URDF with its own parser and its own dynamics (mujoco_model.hpp): a Plant
// (plant.hpp's concept), so that ContourLoop (closed_loop.hpp) runs it or arbor's.
//   - MuJoCo steps at its own rate (MujocoPlantOptions::dt, 1 ms by default, h / dt steps per
//     0.02 s sample) with its own integrator (RK4 by default; `euler`: MuJoCo's semi-implicit
//     Euler, implicit in the joint damping).
//   - OCP-FD: the torque of u_0 (or a TorqueLaw's, per step: plant.hpp) is applied as qfrc_applied
//     (joint torque, no clipping), held over
//     the sample. OCP-ID: the inner 1 kHz computed-torque loop of plant.hpp, tau = rnea(q, qd,
//     qdd_cmd) on the controller's (nominal) arbor model at each MuJoCo step.
//   - Unknown to the controller: a point mass at the end-effector frame (the 0.5 kg of
//     `--mismatch`, written into the URDF as a link on a fixed joint), and damping, armature and
//     frictionloss on every joint.
//   - Events in the middle of the task (issue 59), at the plant's own time (0 at init(), counted
//     per MuJoCo step): the payload attached at `payload_on` and released at `payload_off` (the
//     fused body's mass, centre of mass and inertia switched between MuJoCo's own values with and
//     without it: the model is compiled both ways at init()), and a push: a force of
//     `push_force` N along world +x at the centre of mass of `push_link` (xfrc_applied) for
//     `push_duration` s from `push_at`.
//   - x is the plant's state [q, qd, s, sd] in arbor's joint order (mapped by joint name); each
//     sample starts MuJoCo from x. s and sd integrate the applied sdd exactly (as plant.hpp).
//   - The end-effector position and rotation error are those of the task's kinematics (arbor's
//     forward kinematics of the nominal Gen3) at MuJoCo's q: the kinematics agree to 1e-15
//     (tests/plant), the payload does not move the frame.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"
#include "mujoco_model.hpp"
#include "plant.hpp"
#include "task.hpp"

namespace contour {

/// How the MuJoCo plant is built (the demo's options --plant-dt, --plant-integrator, --damping,
/// --armature, --frictionloss, --mismatch).
struct MujocoPlantOptions {
  std::string urdf;                ///< the Gen3's URDF file
  double dt = 1e-3;                ///< MuJoCo's time step [s] (h is a whole number of them)
  bool euler = false;              ///< MuJoCo's Euler integrator instead of RK4
  double payload = 0;              ///< point mass at the end-effector frame [kg]
  mujoco::JointProperties joints;  ///< damping, armature, frictionloss on every joint
  double payload_on = -1;          ///< the payload is attached at this time [s] (< 0: from 0)
  double payload_off = -1;         ///< and released at this time [s] (< 0: never)
  double push_at = -1;             ///< a push starts at this time [s] (< 0: none)
  double push_force = 10;          ///< its force along world +x [N]
  double push_duration = 0.1;      ///< its length [s]
  std::string push_link = "forearm_link";  ///< the link pushed (at its centre of mass)
};

class MujocoPlant {
 public:
  using Vx = VecN<double, nx>;
  using Vq = VecN<double, nq>;

  Vx x = Vx::Zero();
  arbor::Data<Robot, double> nominal;  ///< the nominal model (computed torque of OCP-ID)
  Vq tau_applied = Vq::Zero();         ///< the torque of the last MuJoCo step
  Vq tau_peak = Vq::Zero();            ///< max |tau| over the last sample's steps

  /// Loads the model; false with a message in err.
  bool init(const MujocoPlantOptions& o, std::string& err) {
    opt_ = o;
    substeps_ = int(std::lround(h / o.dt));
    if (substeps_ < 1 || std::fabs(substeps_ * o.dt - h) > 1e-12) {
      err = "the plant's time step must divide h = 0.02 s";
      return false;
    }
    mujoco::PointMass pm;
    if (o.payload > 0) {
      // the end-effector frame's link (the URDF's end_effector_link): the mass at its origin
      pm.link = std::string(Robot::frames[std::size_t(ee_frame)].name);
      pm.mass = o.payload;
    }
    if (!mj_.load_file(o.urdf, pm, o.joints, err))
      return false;
    mj_.m->opt.timestep = o.dt;
    mj_.m->opt.integrator = o.euler ? mjINT_EULER : mjINT_RK4;
    t_ = 0;
    payload_body_ = -1;
    if (o.payload > 0 && (o.payload_on > 0 || o.payload_off >= 0)) {
      // MuJoCo's own fused body without the payload: the values to switch to
      mujoco::MujocoModel<Robot> bare;
      if (!bare.load_file(o.urdf, mujoco::PointMass{}, o.joints, err))
        return false;
      for (int b = 0; b < mj_.m->nbody && b < bare.m->nbody; ++b)
        if (mj_.m->body_mass[b] != bare.m->body_mass[b])
          payload_body_ = b;
      if (payload_body_ < 0) {
        err = "the payload changed no body's mass";
        return false;
      }
      with_.read(mj_.m, payload_body_);
      without_.read(bare.m, payload_body_);
      attached_ = true;
      set_payload(o.payload_on <= 0);
    }
    push_body_ = -1;
    if (o.push_at >= 0) {
      push_body_ = mj_name2id(mj_.m, mjOBJ_BODY, o.push_link.c_str());
      if (push_body_ < 0) {
        err = "no body named " + o.push_link + " to push";
        return false;
      }
    }
    return true;
  }

  /// The plant's time [s] (0 at init()).
  double time() const { return t_; }
  /// The payload is attached now.
  bool payload_attached() const { return payload_body_ < 0 ? opt_.payload > 0 : attached_; }

  /// One sample of length h: u = [tau, sdd] (fd) or [qdd_cmd, sdd] (id); after each MuJoCo step
  /// hook(q, qd, tau) with the state it reached and the torque it applied (plant.hpp's Plant).
  template <class Hook = NoSubstepHook>
  void step(Formulation form, const VecN<double, nu>& u, Hook&& hook = {}, TorqueLaw law = {}) {
    tau_peak.setZero();
    mj_.set_state(x.head<nq>(), x.segment<nq>(nq));
    mjData* d = mj_.d;
    d->time = 0;
    mju_zero(d->qacc_warmstart, mj_.m->nv);
    const int bad = d->warning[mjWARN_BADQACC].number;
    for (int k = 0; k < substeps_; ++k) {
      events();
      Vq tau;
      if (form == Formulation::fd) {
        tau = u.head<nq>();
        law(k, tau);
      } else {
        Vq q, v;
        for (int i = 0; i < nq; ++i) {
          q[i] = mj_.q(i);
          v[i] = mj_.v(i);
        }
        tau = arbor::rnea<Robot>(nominal, q, v, Vq(u.head<nq>()));
      }
      tau_applied = tau;
      tau_peak = tau_peak.cwiseMax(tau.cwiseAbs());
      mj_.set_torque(tau);
      mj_step(mj_.m, d);
      t_ += opt_.dt;
      Vq qk, vk;
      for (int i = 0; i < nq; ++i) {
        qk[i] = mj_.q(i);
        vk[i] = mj_.v(i);
      }
      hook(qk, vk, tau);
    }
    for (int i = 0; i < nq; ++i) {
      x[i] = mj_.q(i);
      x[nq + i] = mj_.v(i);
    }
    // MuJoCo resets its state on a non-finite acceleration: report it as one
    if (d->warning[mjWARN_BADQACC].number != bad)
      x.head<2 * nq>().setConstant(std::numeric_limits<double>::quiet_NaN());
    const double sdd = u[7];
    x[14] += h * x[15] + 0.5 * h * h * sdd;
    x[15] += h * sdd;
  }

  /// End-effector position at the plant's q (the task's kinematics).
  VecN<double, 3> ee_position() {
    arbor::forward_kinematics<Robot>(kin_, Vq(x.head<nq>()));
    return arbor::frame_placement<Robot>(kin_, ee_frame).p;
  }
  /// End-effector rotation error against the reference.
  VecN<double, 3> rotation_error(const Reference& ref) {
    arbor::forward_kinematics<Robot>(kin_, Vq(x.head<nq>()));
    return contour::rotation_error<double>(ref, arbor::frame_placement<Robot>(kin_, ee_frame).R);
  }
  /// MuJoCo's time step [s].
  double substep_dt() const { return opt_.dt; }

  const MujocoPlantOptions& options() const { return opt_; }
  int substeps() const { return substeps_; }
  const mujoco::MujocoModel<Robot>& model() const { return mj_; }

 private:
  /// The payload's body: mass, centre of mass and inertia (MuJoCo's fused values).
  struct BodyInertia {
    double mass = 0, ipos[3]{}, iquat[4]{}, inertia[3]{};
    void read(const mjModel* m, int b) {
      mass = m->body_mass[b];
      for (int i = 0; i < 3; ++i) {
        ipos[i] = m->body_ipos[3 * b + i];
        inertia[i] = m->body_inertia[3 * b + i];
      }
      for (int i = 0; i < 4; ++i)
        iquat[i] = m->body_iquat[4 * b + i];
    }
    void write(mjModel* m, int b) const {
      m->body_mass[b] = mass;
      for (int i = 0; i < 3; ++i) {
        m->body_ipos[3 * b + i] = ipos[i];
        m->body_inertia[3 * b + i] = inertia[i];
      }
      for (int i = 0; i < 4; ++i)
        m->body_iquat[4 * b + i] = iquat[i];
    }
  };

  void set_payload(bool on) {
    if (payload_body_ < 0 || on == attached_)
      return;
    (on ? with_ : without_).write(mj_.m, payload_body_);
    attached_ = on;
  }

  /// The events due at the plant's time, before a MuJoCo step (half a step of slack against the
  /// time's rounding).
  void events() {
    const double t = t_ + 0.5 * opt_.dt;
    if (payload_body_ >= 0)
      set_payload((opt_.payload_on <= 0 || t >= opt_.payload_on) &&
                  (opt_.payload_off < 0 || t < opt_.payload_off));
    if (push_body_ >= 0) {
      const bool on = t >= opt_.push_at && t < opt_.push_at + opt_.push_duration;
      mj_.d->xfrc_applied[6 * push_body_] = on ? opt_.push_force : 0.0;
    }
  }

  MujocoPlantOptions opt_;
  double t_ = 0;
  int payload_body_ = -1, push_body_ = -1;
  bool attached_ = true;
  BodyInertia with_, without_;
  int substeps_ = 20;
  mujoco::MujocoModel<Robot> mj_;
  arbor::Data<Robot, double> kin_;
};
static_assert(Plant<MujocoPlant>);

}  // namespace contour

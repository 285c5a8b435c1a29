// arbor: a payload set at run time: a rigid body (mass, centre of mass, rotational inertia)
// attached to an operational frame, whose inertia every inertia-dependent algorithm adds to the
// frame's body (rnea, gravity, nle, crba, aba, minverse, rnea_derivatives, aba_derivatives, the
// second-order routines and the AD layer's function objects), without regenerating the robot.
//
// The robot's body inertias stay compile-time constants (the algorithms specialise on their
// zeros); the payload is one run-time spatial inertia in the frame's body frame, held in
// Data::payload. Each algorithm tests payload.active once and calls the payload's terms out of
// line (ARBOR_NOINLINE, so that the plain path keeps the compiler's inlining budget; crba's, one
// inertia sum, inline): rnea, crba and the derivative and second-order forward passes patch the
// body's entries between two unrolled passes; aba and minverse, where the body's inertia enters in the middle of their
// backward sweep (the articulated inertias), call a second instantiation of that sweep. With no
// payload set, each algorithm runs the code it ran before plus that one test (docs/api.md,
// section 8: instruction counts).
#pragma once

#include <type_traits>

#include "arbor/dynamics/data.hpp"
#include "arbor/spatial/articulated_inertia.hpp"
#include "arbor/spatial/inertia.hpp"

namespace arbor {

namespace detail {
/// Whether body b's constant inertia is zero (its forward-pass terms are skipped at compile time).
template <class R>
constexpr bool body_massless(int b) {
  return R::body_inertia[b].mass == 0.0;
}
}  // namespace detail

/// Sets the payload of data: mass [kg], centre of mass com and rotational inertia Ic about the
/// centre of mass, both in operational frame `frame` (R::frame_id::<link>, or
/// model::frame_index<R>(name)). Replaces any previous payload. Returns false (and clears the
/// payload) when the frame index is out of range or the mass is negative. A payload on a frame of
/// the fixed base is accepted and changes nothing (the base does not move).
template <Robot R, class Scalar>
bool set_payload(Data<R, Scalar>& d, int frame, const std::type_identity_t<Scalar>& mass,
                 const std::type_identity_t<Vec3<Scalar>>& com,
                 const std::type_identity_t<Mat3<Scalar>>& Ic) {
  Payload<Scalar>& p = d.payload;
  p = Payload<Scalar>{};
  if (frame < 0 || frame >= R::nf || !(mass >= Scalar(0)))
    return false;
  const model::Frame& f = R::frames[frame];
  p.frame = frame;
  p.body = f.body;
  if (f.body < 0)
    return true;  // on the fixed base: no dynamic effect
  // the frame's placement in its body: c_b = R c + t, Ic_b = R Ic R^T
  Mat3<Scalar> Rf;
  Vec3<Scalar> tf;
  for (int r = 0; r < 3; ++r) {
    tf[r] = Scalar(f.placement.p[r]);
    for (int c = 0; c < 3; ++c)
      Rf(r, c) = Scalar(f.placement.R[r][c]);
  }
  const Vec3<Scalar> cb = Rf * com + tf;
  const Mat3<Scalar> Icb = Rf * Ic * Rf.transpose();
  p.Y = spatial::Inertia<Scalar>::FromMassComInertia(mass, cb, Icb);
  p.active = true;
  return true;
}

/// Removes the payload: the algorithms run the robot as generated.
template <Robot R, class Scalar>
void clear_payload(Data<R, Scalar>& d) {
  d.payload = Payload<Scalar>{};
}

namespace detail {

/// The payload as an articulated inertia (A = m 1, B = -[h], C = Io), added to Y.
template <class Scalar>
ARBOR_INLINE void add_payload_art(spatial::ArticulatedInertia<Scalar>& Y,
                                  const spatial::Inertia<Scalar>& P) {
  for (int r = 0; r < 3; ++r) {
    Y.A(r, r) += P.m;
    for (int c = 0; c < 3; ++c)
      Y.C(r, c) += P.Io(r, c);
  }
  // -[h] = [[0, h2, -h1], [-h2, 0, h0], [h1, -h0, 0]]
  Y.B(0, 1) += P.h[2];
  Y.B(0, 2) -= P.h[1];
  Y.B(1, 0) -= P.h[2];
  Y.B(1, 2) += P.h[0];
  Y.B(2, 0) += P.h[1];
  Y.B(2, 1) -= P.h[0];
}

/// The payload's inertia in the world frame (body placement data.oMi[body]).
template <class R, class Scalar>
ARBOR_INLINE spatial::Inertia<Scalar> payload_world(const Data<R, Scalar>& d) {
  return d.payload.Y.se3Action(d.oMi[d.payload.body]);
}

}  // namespace detail

}  // namespace arbor

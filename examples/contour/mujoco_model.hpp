// MuJoCo (Debian's libmujoco-dev, 2.2.2) loading a robot's URDF with its own parser, for the
// contour example's independent plant (mujoco_plant.hpp) and the test that MuJoCo's and arbor's
// dynamics agree (tests/plant). Host code of the example: it allocates, reads files and uses
// std::string; nothing in include/arbor depends on it.
//
//   MujocoModel<R> mj;                         // R: arbor's generated robot of the same URDF
//   std::string err;
//   if (!mj.load_file("kinova_gen3.urdf", {}, err)) ...
//   mj.set_state(q, qd); mj.set_torque(tau); mj_forward(mj.m, mj.d); mj.qacc() ...
//
// What the URDF becomes (mujoco_urdf()): <visual> and <collision> elements removed (no meshes
// are read, no contacts can exist), and a <mujoco><compiler .../></mujoco> hint that keeps the
// URDF's inertias as written: inertiafromgeom="false" (a link without <inertial> is massless, as
// in arbor's generator, never a mass made up from geometry), balanceinertia="false",
// boundmass = boundinertia = 0; fusestatic="true" (links on fixed joints merged into their
// moving parent: the same mass properties, as arbor's generator does). After loading: contacts
// and joint limits disabled (the limits are the controller's business; a limited URDF joint
// would otherwise be a MuJoCo limit constraint), gravity (0, 0, -9.81), and every joint's
// armature, damping and frictionloss set by the caller (zero by default: the URDF's <dynamics>
// damping/friction, which MuJoCo reads and arbor does not, are overridden). Joints are mapped to
// arbor's order by name (R::joint_names), never by position.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

namespace contour::mujoco {

/// A point mass fixed to a link (the payload of `--mismatch`), written into the URDF as a link
/// on a fixed joint (MuJoCo merges it into the moving parent body).
struct PointMass {
  std::string link;             ///< the link it is fixed to (URDF name); empty: none
  double mass = 0;              ///< [kg]
  std::array<double, 3> xyz{};  ///< position in the link's frame [m]
};

/// Per-joint properties unknown to the controller (the same value on every joint).
struct JointProperties {
  double damping = 0;       ///< viscous damping [N m s / rad]
  double armature = 0;      ///< rotor inertia added to M's diagonal [kg m^2]
  double frictionloss = 0;  ///< dry friction [N m] (MuJoCo's frictionloss constraint)
};

namespace detail {
/// Removes every <tag ...>...</tag> and <tag .../> element from the text.
inline void strip_elements(std::string& s, const std::string& tag) {
  const std::string open = "<" + tag, close = "</" + tag + ">";
  std::size_t pos = 0;
  while ((pos = s.find(open, pos)) != std::string::npos) {
    const char next = pos + open.size() < s.size() ? s[pos + open.size()] : '\0';
    if (next != ' ' && next != '>' && next != '/' && next != '\n' && next != '\t' && next != '\r') {
      pos += open.size();  // another tag with this prefix (e.g. <visualization>)
      continue;
    }
    const std::size_t gt = s.find('>', pos);
    if (gt == std::string::npos)
      return;
    std::size_t end;
    if (s[gt - 1] == '/') {
      end = gt + 1;
    } else {
      const std::size_t c = s.find(close, gt);
      if (c == std::string::npos)
        return;
      end = c + close.size();
    }
    s.erase(pos, end - pos);
  }
}

inline std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
}  // namespace detail

/// The URDF text MuJoCo loads (see the top of this file); an optional point mass added.
inline std::string mujoco_urdf(std::string urdf, const PointMass& payload = {}) {
  detail::strip_elements(urdf, "visual");
  detail::strip_elements(urdf, "collision");
  detail::strip_elements(urdf, "mujoco");  // a hint of the file's own: ours replaces it
  const std::size_t robot = urdf.find("<robot");
  const std::size_t gt = robot == std::string::npos ? robot : urdf.find('>', robot);
  if (gt == std::string::npos)
    return {};
  urdf.insert(gt + 1,
              "\n  <mujoco><compiler discardvisual=\"true\" inertiafromgeom=\"false\" "
              "balanceinertia=\"false\" boundmass=\"0\" boundinertia=\"0\" fusestatic=\"true\" "
              "strippath=\"true\"/></mujoco>\n");
  if (!payload.link.empty() && payload.mass > 0) {
    const std::size_t end = urdf.rfind("</robot>");
    if (end == std::string::npos)
      return {};
    const auto& p = payload.xyz;
    urdf.insert(end, "  <link name=\"arbor_payload\"><inertial><origin xyz=\"" + detail::num(p[0]) +
                         " " + detail::num(p[1]) + " " + detail::num(p[2]) + "\"/><mass value=\"" +
                         detail::num(payload.mass) +
                         "\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" "
                         "izz=\"0\"/></inertial></link>\n  <joint name=\"arbor_payload_joint\" "
                         "type=\"fixed\"><parent link=\"" +
                         payload.link +
                         "\"/><child link=\"arbor_payload\"/><origin xyz=\"0 0 0\"/></joint>\n");
  }
  return urdf;
}

/// mjModel and mjData of robot R's URDF, with the joint map to arbor's order.
template <class R>
class MujocoModel {
 public:
  mjModel* m = nullptr;
  mjData* d = nullptr;
  std::array<int, R::nq> qpos_adr{};  ///< MuJoCo's qpos index of arbor's joint i
  std::array<int, R::nv> dof_adr{};   ///< MuJoCo's dof (qvel, qacc, M) index of arbor's joint i

  MujocoModel() = default;
  MujocoModel(const MujocoModel&) = delete;
  MujocoModel& operator=(const MujocoModel&) = delete;
  ~MujocoModel() { release(); }

  /// Loads URDF text (preprocessed by mujoco_urdf); false with a message in err on failure.
  bool load(const std::string& urdf_text, const JointProperties& jp, std::string& err) {
    release();
    if (urdf_text.empty()) {
      err = "not a URDF (no <robot> element)";
      return false;
    }
    // The text goes to MuJoCo through its virtual file system (no file written).
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    const char* name = "arbor_plant.urdf";
    if (mj_makeEmptyFileVFS(vfs.get(), name, int(urdf_text.size())) != 0) {
      err = "MuJoCo's virtual file system is full";
      return false;
    }
    const int f = mj_findFileVFS(vfs.get(), name);
    std::memcpy(vfs->filedata[f], urdf_text.data(), urdf_text.size());
    char msg[1000] = "";
    m = mj_loadXML(name, vfs.get(), msg, sizeof msg);
    mj_deleteVFS(vfs.get());
    if (!m) {
      err = std::string("MuJoCo could not load the URDF: ") + msg;
      return false;
    }
    if (m->nq != R::nq || m->nv != R::nv) {
      err = "MuJoCo's model has nq = " + std::to_string(m->nq) + ", nv = " + std::to_string(m->nv) +
            " where arbor's has " + std::to_string(R::nq) + ", " + std::to_string(R::nv);
      release();
      return false;
    }
    for (int i = 0; i < R::nq; ++i) {
      const std::string jn(R::joint_names[std::size_t(i)]);
      const int id = mj_name2id(m, mjOBJ_JOINT, jn.c_str());
      if (id < 0 || (m->jnt_type[id] != mjJNT_HINGE && m->jnt_type[id] != mjJNT_SLIDE)) {
        err = "MuJoCo's model has no hinge or slide joint named \"" + jn + "\"";
        release();
        return false;
      }
      qpos_adr[std::size_t(i)] = m->jnt_qposadr[id];
      dof_adr[std::size_t(i)] = m->jnt_dofadr[id];
    }
    m->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_LIMIT | mjDSBL_EQUALITY;
    m->opt.gravity[0] = m->opt.gravity[1] = 0;
    m->opt.gravity[2] = -9.81;
    for (int j = 0; j < m->nv; ++j) {
      m->dof_damping[j] = jp.damping;
      m->dof_armature[j] = jp.armature;
      m->dof_frictionloss[j] = jp.frictionloss;
    }
    for (int j = 0; j < m->njnt; ++j)
      m->jnt_stiffness[j] = 0;
    d = mj_makeData(m);
    return d != nullptr;
  }

  /// Reads a URDF file, preprocesses it (mujoco_urdf) and loads it.
  bool load_file(const std::string& path, const PointMass& payload, const JointProperties& jp,
                 std::string& err) {
    std::ifstream in(path);
    if (!in) {
      err = "cannot read " + path;
      return false;
    }
    std::stringstream ss;
    ss << in.rdbuf();
    if (!load(mujoco_urdf(ss.str(), payload), jp, err)) {
      err = path + ": " + err;
      return false;
    }
    return true;
  }

  /// Sets qpos, qvel from arbor's order.
  template <class Q, class V>
  void set_state(const Q& q, const V& v) {
    for (int i = 0; i < R::nq; ++i)
      d->qpos[qpos_adr[std::size_t(i)]] = q[i];
    for (int i = 0; i < R::nv; ++i)
      d->qvel[dof_adr[std::size_t(i)]] = v[i];
  }
  /// Sets the applied joint torques (qfrc_applied) from arbor's order.
  template <class T>
  void set_torque(const T& tau) {
    for (int i = 0; i < R::nv; ++i)
      d->qfrc_applied[dof_adr[std::size_t(i)]] = tau[i];
  }
  /// qpos, qvel, qacc in arbor's order.
  double q(int i) const { return d->qpos[qpos_adr[std::size_t(i)]]; }
  double v(int i) const { return d->qvel[dof_adr[std::size_t(i)]]; }
  double a(int i) const { return d->qacc[dof_adr[std::size_t(i)]]; }
  /// M(i, j) in arbor's order into out (R::nv x R::nv, any matrix with operator()); call after
  /// mj_forward.
  template <class Mat>
  void mass_matrix(Mat& out) const {
    std::unique_ptr<mjtNum[]> full(new mjtNum[std::size_t(m->nv) * std::size_t(m->nv)]);
    mj_fullM(m, full.get(), d->qM);
    for (int i = 0; i < R::nv; ++i)
      for (int j = 0; j < R::nv; ++j)
        out(i, j) = full[std::size_t(dof_adr[std::size_t(i)] * m->nv + dof_adr[std::size_t(j)])];
  }

 private:
  void release() {
    if (d)
      mj_deleteData(d);
    if (m)
      mj_deleteModel(m);
    d = nullptr;
    m = nullptr;
  }
};

}  // namespace contour::mujoco

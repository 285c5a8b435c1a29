// arbor-gen: URDF (parsed by urdfdom) -> a kinematic tree of one-DoF bodies -> a C++ header of
// constexpr data satisfying arbor::model::RobotModel (include/arbor/model/robot.hpp).
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace arbor::gen {

inline constexpr const char* kVersion = "0.1.0";

/// Any problem with the input or the options: the message names the element; no output is made.
class GenError : public std::runtime_error {
 public:
  explicit GenError(const std::string& what) : std::runtime_error(what) {}
};

/// Command-line options (see `arbor-gen --help`).
struct Options {
  std::string input;                 ///< URDF path
  std::string output;                ///< header path, "-" for stdout
  std::string name;                  ///< struct name; derived from the URDF if empty
  std::string ns = "arbor::robots";  ///< namespace of the struct
  std::string root;                  ///< root link; the URDF root if empty
  std::vector<std::string> tips;     ///< keep only chains root -> these links
  std::vector<std::pair<std::string, double>> locks;  ///< joints made fixed at these positions
  bool lock_mimic = false;      ///< lock every mimic group at its master's default position
  bool strict_inertia = false;  ///< inconsistent or round-off inertias are errors
  bool fix_inertia = false;     ///< inconsistent inertias replaced by the nearest consistent one
  double snap = 0;              ///< rotations/axes within this angle [rad] of aligned made exact
  bool summary = false;         ///< print a summary instead of (or besides) writing a header
};

/// Tolerances at which the summary counts how many placements `--snap` would make exact.
inline constexpr std::array<double, 6> kSnapLadder = {1e-9, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3};
/// Misalignments up to this [rad] are taken for decimal rounding of an exact angle (pi/2 written
/// 1.5708 is 3.7e-6 off) and named in a note suggesting --snap; larger ones look deliberate.
inline constexpr double kRoundedAngleMax = 1e-4;

using Vec3 = std::array<double, 3>;
using Mat3 = std::array<Vec3, 3>;

/// Rigid transform: x_parent = R x_child + p.
struct Transform {
  Mat3 R{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};  ///< rotation
  Vec3 p{0, 0, 0};                            ///< translation
};

/// Mass, centre of mass and rotational inertia about the centre of mass (frame axes).
struct MassProps {
  double mass = 0;  ///< kg
  Vec3 com{0, 0, 0};
  Mat3 I{};
};

enum class Kind { RX, RY, RZ, RU, PX, PY, PZ, PU };

/// One body of the tree (its movable joint and the links lumped into it).
struct Body {
  std::string joint;     ///< URDF joint name
  std::string link;      ///< URDF child link name
  int parent = -1;       ///< parent body, -1 = fixed base
  Kind kind = Kind::RZ;  ///< joint kind
  Vec3 axis{0, 0, 1};    ///< unit axis in the joint frame
  Transform placement;   ///< joint frame in the parent body frame at q = 0
  MassProps inertia;     ///< lumped inertia in the body frame
  double lower = 0, upper = 0, velocity = 0, effort = 0;  ///< limits (inf where none)
  bool continuous = false;                                ///< URDF type was continuous
};

/// An operational frame: one per URDF link kept.
struct FrameDesc {
  std::string link;     ///< URDF link name
  int body = -1;        ///< body it moves with, -1 = fixed base
  Transform placement;  ///< placement in that body's frame
};

/// The tree extracted from a URDF, in depth-first URDF document order (parent < child).
struct RobotDesc {
  std::string urdf_name;              ///< <robot name=...>
  std::string root_link;              ///< the fixed base link
  std::vector<Body> bodies;           ///< movable bodies
  MassProps base;                     ///< inertia lumped into the fixed base
  std::vector<FrameDesc> frames;      ///< every link kept, in depth-first order
  std::vector<std::string> notes;     ///< non-fatal remarks (dropped links, locked joints...)
  std::vector<std::string> warnings;  ///< accepted defects of the input (one per link and defect)
  /// Angle [rad] from each joint origin rotation or joint axis of the URDF to the nearest
  /// axis-aligned one, for those not aligned (kAxisAlignedTol, snap.hpp); after --snap.
  std::vector<double> misalignment;
  int snapped = 0;               ///< rotations and axes made exact by --snap
  double snap_max_angle = 0;     ///< largest change of those [rad]
  double snap_max_position = 0;  ///< largest change of a frame's position at q = 0 [m]
  double snap_max_rotation = 0;  ///< largest change of a frame's orientation at q = 0 [rad]
};

/// Parses URDF text with urdfdom and builds the tree. `source` names the file in messages.
/// Throws GenError with a message naming the offending element.
RobotDesc build_robot(const std::string& urdf_text, const Options& opt, const std::string& source);

/// Information written into the banner.
struct Provenance {
  std::string file_name;  ///< base name of the URDF
  std::string sha256;     ///< hex digest of the URDF bytes
};

/// The header text for a built robot (deterministic: same input, same bytes).
std::string emit_header(const RobotDesc& robot, const Options& opt, const Provenance& prov);

/// The text of `arbor-gen --summary`: bodies, DoF, joint kinds, masses, limits, how many
/// placements a snap tolerance would make exact, notes and warnings.
std::string summary_text(const RobotDesc& robot, const Options& opt, const Provenance& prov);

/// Turns any string into a valid C++ identifier (invalid characters -> '_', leading digit and
/// keywords handled). `pascal` gives PascalCase (for type names).
std::string sanitize_identifier(const std::string& s, bool pascal);

/// True when `s` is a valid, non-reserved C++ identifier.
bool is_identifier(const std::string& s);

}  // namespace arbor::gen

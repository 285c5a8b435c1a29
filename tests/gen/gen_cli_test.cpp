// arbor-gen as a user runs it: bad inputs give one clear message naming the file and the element,
// a non-zero exit and no output file; good inputs give deterministic headers.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace {

const std::string kGen = ARBOR_GEN_EXE;
const std::string kData = ARBOR_GEN_DATA;
const std::string kRobots = ARBOR_ROBOTS_DIR;

struct GenResult {
  int status;       ///< exit status
  std::string out;  ///< standard output
  std::string err;  ///< standard error
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh, empty scratch folder per test.
fs::path scratch() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(info->test_suite_name()) + "_" + info->name();
  for (char& c : name)
    if (c == '/')
      c = '_';
  const fs::path dir = fs::path(ARBOR_TEST_TMP) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

GenResult run(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd =
      "'" + kGen + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int raw = std::system(cmd.c_str());
  GenResult r{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
  fs::remove(out);
  fs::remove(err);
  return r;
}

std::size_t files_in(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
    ++n;
  return n;
}

/// The lines of `text` that start with `prefix`.
std::vector<std::string> lines_with(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0)
      out.push_back(line);
  return out;
}

// ---- malformed URDFs ----------------------------------------------------------------------
struct BadCase {
  const char* file;      ///< file under tests/gen/data/bad
  const char* expected;  ///< a piece of the message that names the problem
};

class BadUrdf : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadUrdf, ClearMessageNonZeroExitNoOutput) {
  const fs::path dir = scratch();
  const std::string input = kData + "/bad/" + GetParam().file;
  const fs::path header = dir / "robot.hpp";
  const GenResult r = run("'" + input + "' -o '" + header.string() + "'", dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err.rfind("arbor-gen: error: " + input + ": ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(GetParam().expected), std::string::npos)
      << "expected '" << GetParam().expected << "' in:\n"
      << r.err;
  EXPECT_FALSE(fs::exists(header));
  EXPECT_EQ(files_in(dir), 0u) << "a temporary file was left behind";
  EXPECT_TRUE(r.out.empty());
}

INSTANTIATE_TEST_SUITE_P(
    Generator, BadUrdf,
    ::testing::Values(BadCase{"xml_syntax.urdf", "XML syntax error at line 6"},
                      BadCase{"missing_parent.urdf", "parent link [nowhere] of joint [j1]"},
                      BadCase{"missing_child.urdf", "child link [ghost] of joint [j1] not found"},
                      BadCase{"cycle.urdf", "has a cycle: b <- c <- b"},
                      BadCase{"two_roots.urdf", "Two root links found: [base] and [other]"},
                      BadCase{"zero_axis.urdf", "revolute joint 'j0': axis is the zero vector"},
                      BadCase{"negative_mass.urdf", "link 'a': negative mass -2 kg"},
                      BadCase{"nonfinite.urdf", "Unable to parse component [nan]"},
                      BadCase{"bad_number.urdf", "mass [1.2.3] is not a float"},
                      BadCase{"unknown_type.urdf", "Joint [j0] has no known type [ball]"},
                      BadCase{"mimic.urdf", "revolute joint 'j1' mimics joint 'j0'"},
                      BadCase{"mimic_missing.urdf",
                              "revolute joint 'finger' mimics joint 'ghost', which does not exist"},
                      BadCase{"floating.urdf", "floating joint 'free': floating joints are not"},
                      BadCase{"planar.urdf", "planar joint 'slide': planar joints are not"},
                      BadCase{"duplicate_link.urdf", "link 'a' is defined more than once"},
                      BadCase{"massless_subtree.urdf", "joint 'j1' moves no mass"},
                      BadCase{"no_movable.urdf", "no movable joint below root link 'base'"},
                      BadCase{"negative_inertia.urdf",
                              "link 'a': inertia has a negative principal moment -0.05 kg m^2 "
                              "(trace 0.25): not a rotational inertia"},
                      BadCase{"mass_on_axis.urdf",
                              "joint 'spin' moves no inertia about its axis at q = 0"},
                      BadCase{"not_urdf.urdf", "no <robot> element"}),
    [](const auto& info) {
      std::string n = info.param.file;
      return n.substr(0, n.find('.'));
    });

TEST(GeneratorInput, UnreadableFile) {
  const fs::path dir = scratch();
  const GenResult r =
      run("'" + kData + "/bad/does_not_exist.urdf' -o '" + (dir / "x.hpp").string() + "'", dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("does_not_exist.urdf: cannot read: No such file"), std::string::npos)
      << r.err;
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(GeneratorInput, FolderInsteadOfFile) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kData + "' -o '" + (dir / "x.hpp").string() + "'", dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("is a folder, not a URDF file"), std::string::npos) << r.err;
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(GeneratorInput, FailedRunKeepsAnEarlierHeaderIntact) {
  const fs::path dir = scratch();
  const fs::path header = dir / "robot.hpp";
  ASSERT_EQ(run("'" + kData + "/merged.urdf' -o '" + header.string() + "'", dir).status, 0);
  const std::string before = slurp(header);
  EXPECT_EQ(run("'" + kData + "/bad/cycle.urdf' -o '" + header.string() + "'", dir).status, 1);
  EXPECT_EQ(slurp(header), before);
  EXPECT_EQ(files_in(dir), 1u);
}

// ---- options -------------------------------------------------------------------------------
struct OptionCase {
  const char* args;      ///< arguments after the URDF path
  int status;            ///< expected exit status (2 = usage error)
  const char* expected;  ///< a piece of the message
};

class BadOption : public ::testing::TestWithParam<OptionCase> {};

TEST_P(BadOption, Rejected) {
  const fs::path dir = scratch();
  const fs::path header = dir / "robot.hpp";
  const GenResult r =
      run("'" + kRobots + "/yumi.urdf' -o '" + header.string() + "' " + GetParam().args, dir);
  EXPECT_EQ(r.status, GetParam().status);
  EXPECT_NE(r.err.find(GetParam().expected), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(header));
}

INSTANTIATE_TEST_SUITE_P(
    Generator, BadOption,
    ::testing::Values(
        OptionCase{"--lock nosuchjoint=0", 1, "--lock nosuchjoint: no joint of that name"},
        OptionCase{"--lock gripper_r_joint=1 --lock gripper_l_joint=0", 1,
                   "--lock gripper_r_joint=1: outside the joint's limits"},
        OptionCase{"--lock gripper_r_joint", 2, "expected JOINT=VALUE"},
        OptionCase{"--lock gripper_r_joint=abc", 2, "expected JOINT=VALUE"},
        OptionCase{"--lock yumi_link_7_r_joint=0", 1, "joint is already fixed"},
        OptionCase{"--tip nolink", 1, "--tip nolink: no link of that name"},
        OptionCase{"--root nolink", 1, "--root nolink: no link of that name"},
        OptionCase{"--root yumi_link_1_r --tip yumi_link_7_l", 1, "is not below the root link"},
        OptionCase{"--name 3bad", 2, "not a valid C++ identifier"},
        OptionCase{"--name class", 2, "not a valid C++ identifier"},
        OptionCase{"--namespace a::1b", 2, "not a valid C++ namespace"},
        OptionCase{"--frobnicate", 2, "unknown option --frobnicate"},
        OptionCase{"--snap", 2, "--snap needs a value"},
        OptionCase{"--snap 0", 2, "--snap 0: expected a tolerance in (0, 0.1) rad"},
        OptionCase{"--snap -1e-5", 2, "expected a tolerance"},
        OptionCase{"--snap 0.5", 2, "expected a tolerance"},
        OptionCase{"--snap nan", 2, "expected a tolerance"},
        OptionCase{"--strict-inertia --fix-inertia", 2, "exclude each other"}));

TEST(GeneratorOptions, MissingOutputIsAUsageError) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kData + "/merged.urdf'", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no output file"), std::string::npos);
}

TEST(GeneratorOptions, HelpAndVersion) {
  const fs::path dir = scratch();
  const GenResult h = run("--help", dir);
  EXPECT_EQ(h.status, 0);
  EXPECT_NE(h.out.find("usage: arbor-gen"), std::string::npos);
  EXPECT_NE(h.out.find("--lock JOINT=VALUE"), std::string::npos);
  for (const char* flag :
       {"--lock-mimic", "--strict-inertia", "--fix-inertia", "--snap TOL", "--summary"})
    EXPECT_NE(h.out.find(flag), std::string::npos) << flag;
  const GenResult v = run("--version", dir);
  EXPECT_EQ(v.status, 0);
  EXPECT_EQ(v.out.rfind("arbor-gen ", 0), 0u);
}

// ---- the YuMi with grippers: mimic joints -----------------------------------------------------
TEST(GeneratorYumi, MimicJointsAreRejectedByDefault) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kRobots + "/yumi.urdf' -o '" + (dir / "y.hpp").string() + "'", dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("mimics joint 'gripper_r_joint'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--lock gripper_r_joint=VALUE"), std::string::npos) << r.err;
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(GeneratorYumi, LockingTheGrippersSucceeds) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kRobots +
                              "/yumi.urdf' -o - --lock gripper_r_joint=0 "
                              "--lock gripper_l_joint=0.01",
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("static constexpr int nv = 14;"), std::string::npos);
  EXPECT_NE(r.err.find("gripper_r_joint_m mimics locked joint gripper_r_joint"), std::string::npos)
      << r.err;
}

TEST(GeneratorYumi, TipsOnTheArmFlangesSucceed) {
  const fs::path dir = scratch();
  const GenResult r =
      run("'" + kRobots + "/yumi.urdf' -o - --tip yumi_link_7_r --tip yumi_link_7_l", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("static constexpr int nv = 14;"), std::string::npos);
  // The gripper bases are fixed to the flanges: kept (merged into link 7, which joint 6 moves in
  // YuMi's naming). The fingers move (prismatic, not locked): dropped, each with a warning naming
  // the kilograms link 7 loses.
  EXPECT_NE(r.out.find("\"gripper_r_base\""), std::string::npos);
  EXPECT_EQ(r.out.find("gripper_r_finger"), std::string::npos) << "fingers must be dropped";
  for (const char* side : {"r", "l"}) {
    const std::string s = side;
    for (const std::string& joint : {"gripper_" + s + "_joint", "gripper_" + s + "_joint_m"}) {
      const std::string finger =
          joint.back() == 'm' ? "gripper_" + s + "_finger_l" : "gripper_" + s + "_finger_r";
      SCOPED_TRACE(joint);
      EXPECT_NE(r.err.find("--tip: prismatic joint '" + joint + "' below link 'gripper_" + s +
                           "_base' is not on a chain to a tip: its subtree is dropped, and "
                           "moving body 'yumi_link_7_" +
                           s + "' (joint 'yumi_joint_6_" + s + "') loses 0.01 kg (" + finger +
                           " 0.01 kg)"),
                std::string::npos)
          << r.err;
    }
  }
}

// ---- --tip keeps rigidly attached mass (tests/gen/data/gripper.urdf) -------------------------
TEST(GeneratorTip, LockedGripperBelowTheTipIsKeptAndAMovableSubtreeIsAWarningInKg) {
  const fs::path dir = scratch();
  const std::string in = kData + "/gripper.urdf";
  const GenResult r = run("'" + in + "' -o - --tip tool0 --lock gripper_joint=0.02", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto warnings = lines_with(r.err, "arbor-gen: warning: ");
  ASSERT_EQ(warnings.size(), 1u) << r.err;
  EXPECT_EQ(warnings[0],
            "arbor-gen: warning: " + in +
                ": --tip: revolute joint 'camera_pan' below link 'gripper_base' is not on a "
                "chain to a tip: its subtree is dropped, and moving body 'l2' (joint 'j2') loses "
                "0.3 kg (camera 0.3 kg). Keep the mass with --lock camera_pan=VALUE, or name a "
                "link below it with --tip");
  // Mass dropped from the fixed base changes nothing: a note, with its kilograms.
  EXPECT_EQ(lines_with(r.err, "arbor-gen: note: --tip: "),
            std::vector<std::string>{
                "arbor-gen: note: --tip: prismatic joint 'conveyor' below link 'base' is not on "
                "a chain to a tip: its subtree is dropped with 5 kg (cart 5 kg), which hung from "
                "the fixed base: the dynamics are unchanged"});
  EXPECT_NE(r.out.find("// Accepted with 1 warning(s)"), std::string::npos);
  EXPECT_NE(r.out.find("\"finger_r\""), std::string::npos);
  EXPECT_EQ(r.out.find("\"camera\""), std::string::npos);
}

TEST(GeneratorTip, UnlockedFingersAreWarningsNamingEachLinkAndTheTotal) {
  const fs::path dir = scratch();
  const std::string in = kData + "/gripper.urdf";
  const GenResult r = run("'" + in + "' -o - --tip tool0", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto warnings = lines_with(r.err, "arbor-gen: warning: ");
  ASSERT_EQ(warnings.size(), 3u) << r.err;  // gripper_joint, its mimic, camera_pan
  const std::string head = "arbor-gen: warning: " + in + ": --tip: prismatic joint ";
  EXPECT_EQ(warnings[0], head +
                             "'gripper_joint' below link 'gripper_base' is not on a chain to a "
                             "tip: its subtree is dropped, and moving body 'l2' (joint 'j2') "
                             "loses 0.12 kg (finger_l 0.1 kg, pad 0.02 kg). Keep the mass with "
                             "--lock gripper_joint=VALUE, or name a link below it with --tip");
  EXPECT_EQ(warnings[1], head +
                             "'gripper_joint_m' below link 'gripper_base' is not on a chain to a "
                             "tip: its subtree is dropped, and moving body 'l2' (joint 'j2') "
                             "loses 0.1 kg (finger_r 0.1 kg). Keep the mass with --lock "
                             "gripper_joint=VALUE (it mimics that joint) or --lock-mimic, or name "
                             "a link below it with --tip");
  EXPECT_NE(warnings[2].find("'camera_pan'"), std::string::npos);
  EXPECT_NE(r.out.find("// Accepted with 3 warning(s)"), std::string::npos);
}

TEST(GeneratorYumi, LockMimicLocksEveryGripperAtItsZero) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kRobots + "/yumi.urdf' -o - --lock-mimic", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("static constexpr int nv = 14;"), std::string::npos);
  EXPECT_NE(r.out.find("// Option: --lock-mimic"), std::string::npos);
  for (const char* side : {"r", "l"}) {
    const std::string s = side;
    EXPECT_NE(r.err.find("--lock-mimic: locked gripper_" + s +
                         "_joint at 0 (its zero) with its "
                         "mimic joints gripper_" +
                         s + "_joint_m"),
              std::string::npos)
        << r.err;
  }
}

// ---- defects of real robot descriptions (tests/gen/data/real) -----------------------------
const std::string kReal = kData + "/real/";

/// The body_inertia entry of `link` in a generated header: the line after "// <link>".
std::string inertia_entry(const std::string& header, const std::string& link) {
  const std::string marker = "      // " + link + "\n";
  const auto at = header.find(marker, header.find("body_inertia"));
  if (at == std::string::npos)
    return "";
  const auto begin = at + marker.size();
  const auto end = header.find("}}},", begin);
  return header.substr(begin, end == std::string::npos ? end : end + 4 - begin);
}

TEST(GeneratorDefects, TriangleInequalityIsAcceptedWithOneWarning) {
  const fs::path dir = scratch();
  const std::string in = kReal + "inertia_triangle.urdf";
  const GenResult r = run("'" + in + "' -o '" + (dir / "t.hpp").string() + "'", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto warnings = lines_with(r.err, "arbor-gen: warning: ");
  ASSERT_EQ(warnings.size(), 1u) << r.err;
  EXPECT_EQ(warnings[0],
            "arbor-gen: warning: " + in +
                ": link 'a': inertia violates the triangle inequality (principal moments 0.1, "
                "0.1, 0.5 kg m^2): physically inconsistent; kept as given (--fix-inertia "
                "repairs it, --strict-inertia rejects it)");
  const std::string header = slurp(dir / "t.hpp");
  EXPECT_NE(inertia_entry(header, "a").find("{{0.1, 0.0, 0.0}, {0.0, 0.1, 0.0}, {0.0, 0.0, 0.5}}"),
            std::string::npos)
      << inertia_entry(header, "a");
  EXPECT_NE(header.find("// Accepted with 1 warning(s)"), std::string::npos);
}

TEST(GeneratorDefects, FixInertiaProjectsOntoTheNearestConsistentInertia) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kReal + "inertia_triangle.urdf' -o - --fix-inertia", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // (0.1, 0.1, 0.5) projected onto l0 + l1 = l2: (0.2, 0.2, 0.4); change 0.1 * sqrt(3).
  EXPECT_NE(r.err.find("link 'a': inertia violates the triangle inequality (principal moments "
                       "0.1, 0.1, 0.5 kg m^2): physically inconsistent; --fix-inertia: replaced "
                       "by the nearest consistent inertia, principal moments 0.2, 0.2, 0.4 kg "
                       "m^2 (change 0.1732 kg m^2, Frobenius)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(inertia_entry(r.out, "a").find("{{0.2, 0.0, 0.0}, {0.0, 0.2, 0.0}, {0.0, 0.0, 0.4}}"),
            std::string::npos)
      << inertia_entry(r.out, "a");
}

TEST(GeneratorDefects, SingularAllEqualInertiaIsFixedToItsHandDerivedProjection) {
  const fs::path dir = scratch();
  const GenResult w = run("'" + kReal + "inertia_singular.urdf' -o -", dir);
  ASSERT_EQ(w.status, 0) << w.err;
  EXPECT_NE(w.err.find("link 'cover': inertia violates the triangle inequality (principal "
                       "moments 0, 0, 0.0003 kg m^2)"),
            std::string::npos)
      << w.err;
  EXPECT_EQ(lines_with(w.err, "arbor-gen: warning: ").size(), 1u) << w.err;
  const GenResult r = run("'" + kReal + "inertia_singular.urdf' -o - --fix-inertia", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("principal moments 0.0001, 0.0001, 0.0002 kg m^2"), std::string::npos)
      << r.err;
  // The values themselves are checked numerically in defect_dynamics_test.cpp.
}

TEST(GeneratorDefects, RoundOffNegativeMomentIsClampedToZero) {
  const fs::path dir = scratch();
  const std::string in = kReal + "inertia_roundoff.urdf";
  const GenResult r = run("'" + in + "' -o -", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto warnings = lines_with(r.err, "arbor-gen: warning: ");
  ASSERT_EQ(warnings.size(), 1u) << r.err;
  EXPECT_EQ(warnings[0], "arbor-gen: warning: " + in +
                             ": link 'rod': inertia has a round-off negative principal moment "
                             "-5e-20 kg m^2 (exporter's zero?): clamped to zero");
  EXPECT_NE(
      inertia_entry(r.out, "rod").find("{{0.0, 0.0, 0.0}, {0.0, 0.0417, 0.0}, {0.0, 0.0, 0.0417}}"),
      std::string::npos)
      << inertia_entry(r.out, "rod");
}

TEST(GeneratorDefects, StrictInertiaTurnsEachWarningIntoAnError) {
  const fs::path dir = scratch();
  for (const auto& [file, expected] :
       {std::pair<std::string, std::string>{"inertia_triangle.urdf",
                                            "link 'a': inertia violates the triangle inequality"},
        {"inertia_singular.urdf", "link 'cover': inertia violates the triangle inequality"},
        {"inertia_roundoff.urdf",
         "link 'rod': inertia has a round-off negative principal moment"}}) {
    const fs::path header = dir / "s.hpp";
    const GenResult r =
        run("'" + kReal + file + "' -o '" + header.string() + "' --strict-inertia", dir);
    EXPECT_EQ(r.status, 1) << file;
    EXPECT_EQ(r.err.rfind("arbor-gen: error: " + kReal + file + ": " + expected, 0), 0u) << r.err;
    EXPECT_NE(r.err.find("[--strict-inertia]"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(header)) << file;
  }
}

TEST(GeneratorDefects, EverydayExportDetailsPassQuietly) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kReal + "everyday.urdf' -o -", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "") << "no warning and no note expected";
  EXPECT_NE(r.out.find("static constexpr int nv = 2;"), std::string::npos);
  EXPECT_NE(r.out.find("struct EveryDayArm {"), std::string::npos);
  EXPECT_NE(r.out.find("{0.1227, {0.0, 0.0, 0.1},"), std::string::npos) << "mass .1227";
  // The joint 'arm' and the link 'arm' keep their own index structs.
  EXPECT_NE(r.out.find("struct joint_id {\n    static constexpr int arm = 0;"), std::string::npos);
  EXPECT_NE(r.out.find("static constexpr int base_link = 0;"), std::string::npos);
  EXPECT_NE(r.out.find("static constexpr int tool_frame = 2;"), std::string::npos);
  EXPECT_NE(r.out.find("static constexpr int elbow_pitch = 1;"), std::string::npos);
}

TEST(GeneratorDefects, MimicGroupsWithoutTheFlagNameTheFlag) {
  const fs::path dir = scratch();
  const GenResult r =
      run("'" + kReal + "mimic_hand.urdf' -o '" + (dir / "h.hpp").string() + "'", dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("prismatic joint 'grip_mirror' mimics joint 'grip': mimic joints are not "
                       "supported. Lock every mimic group with --lock-mimic"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(GeneratorDefects, LockMimicLocksEachGroupAtTheStatedValue) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kReal + "mimic_hand.urdf' -o - --lock-mimic", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("static constexpr int nv = 2;"), std::string::npos);
  const auto notes = lines_with(r.err, "arbor-gen: note: ");
  const std::vector<std::string> expected = {
      "arbor-gen: note: --lock-mimic: locked grip at 0 (its zero) with its mimic joints "
      "grip_mirror",
      "arbor-gen: note: --lock-mimic: locked thumb at 0.4 (the middle of its range [0.2, 0.6]) "
      "with its mimic joints thumb_nail, thumb_tip",
      "arbor-gen: note: joint grip_mirror mimics locked joint grip: locked at 0.000000",
      "arbor-gen: note: joint thumb_tip mimics locked joint thumb: locked at 0.900000",
      "arbor-gen: note: joint thumb_nail mimics locked joint thumb_tip: locked at 0.450000"};
  EXPECT_EQ(notes, expected) << r.err;
  EXPECT_TRUE(lines_with(r.err, "arbor-gen: warning: ").empty()) << r.err;
}

TEST(GeneratorDefects, AnExplicitLockOfAMasterWinsOverLockMimic) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kReal + "mimic_hand.urdf' -o - --lock-mimic --lock thumb=0.3", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("--lock-mimic: thumb locked at 0.3 by --lock, with its mimic joints "
                       "thumb_nail, thumb_tip"),
            std::string::npos)
      << r.err;
  // 2 * 0.3 + 0.1 = 0.7, then 0.5 * 0.7 = 0.35.
  EXPECT_NE(r.err.find("joint thumb_nail mimics locked joint thumb_tip: locked at 0.350000"),
            std::string::npos)
      << r.err;
}

TEST(GeneratorDefects, MimicCyclesAreRejectedWithAndWithoutLockMimic) {
  const fs::path dir = scratch();
  const std::string in = kData + "/bad/mimic_cycle.urdf";
  for (const char* flags : {"", " --lock-mimic"}) {
    const GenResult r = run("'" + in + "' -o '" + (dir / "c.hpp").string() + "'" + flags, dir);
    EXPECT_EQ(r.status, 1) << flags;
    EXPECT_EQ(
        r.err.rfind("arbor-gen: error: " + in + ": joint 'j1': its mimic joints form a cycle", 0),
        0u)
        << r.err;
    EXPECT_EQ(files_in(dir), 0u);
  }
}

TEST(GeneratorDefects, AMimicCycleHasOneMessageWhicheverStepMeetsIt) {
  // Resolving j1's lock and grouping for --lock-mimic walk the same chain j1 -> j2 -> j1.
  const fs::path dir = scratch();
  const std::string in = kData + "/bad/mimic_cycle.urdf";
  for (const char* flags : {"", " --lock-mimic", " --lock j0=0"}) {
    const GenResult r = run("'" + in + "' -o -" + flags, dir);
    EXPECT_EQ(r.status, 1) << flags;
    EXPECT_EQ(r.err, "arbor-gen: error: " + in +
                         ": joint 'j1': its mimic joints form a cycle through 'j1'\n")
        << flags;
  }
}

TEST(GeneratorDefects, OneToleranceDecidesWhetherAnAxisIsAligned) {
  // tests/gen/data/axis_band.urdf: j0 5e-13 rad off +Z (beyond round-off), j1 5e-14 off +X.
  const fs::path dir = scratch();
  const std::string in = kData + "/axis_band.urdf";
  const GenResult r = run("'" + in + "' -o -", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("arbor-gen: note: 1 joint rotations or axes are within 5e-13 rad of "
                       "axis-aligned (rounded angles?): --snap makes them exact"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("JointKind::revolute_unaligned,  // j0"), std::string::npos);
  EXPECT_NE(r.out.find("JointKind::revolute_x,  // j1"), std::string::npos);
  const GenResult s = run("'" + in + "' -o - --snap 1e-9", dir);
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_NE(s.err.find("--snap 1e-09 made 1 joint rotations and axes exact"), std::string::npos)
      << s.err;
  EXPECT_NE(s.out.find("JointKind::revolute_z,  // j0"), std::string::npos);
}

TEST(GeneratorDefects, RoundedAnglesAreCountedAndNamedWithoutSnap) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kReal + "rounded_angles.urdf' -o -", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // 1.5708 - pi/2 = 3.67320510e-6; -3.1416 + pi = -7.34641021e-6 (the largest).
  EXPECT_NE(r.err.find("arbor-gen: note: 4 joint rotations or axes are within 7.34641e-06 rad of "
                       "axis-aligned (rounded angles?): --snap makes them exact"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("JointKind::revolute_unaligned,  // j3"), std::string::npos);
  const GenResult s = run("'" + kReal + "rounded_angles.urdf' --summary", dir);
  ASSERT_EQ(s.status, 0) << s.err;
  // Misalignments: j2 3.2e-10 (rpy), j3 axis 1e-6, j1 3.67e-6, j3 rpy 7.35e-6.
  EXPECT_NE(s.out.find("  rotations and axes not axis-aligned: 4; --snap TOL would make exact: "
                       "1e-09: 1, 1e-07: 1, 1e-06: 2, 1e-05: 4, 0.0001: 4, 0.001: 4\n"),
            std::string::npos)
      << s.out;
}

TEST(GeneratorDefects, SnapMakesRoundedRotationsAndAxesExact) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kReal + "rounded_angles.urdf' -o - --snap 1e-5", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("--snap makes them exact"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("arbor-gen: note: --snap 1e-05 made 4 joint rotations and axes exact: "
                       "largest change 7.34641e-06 rad; frames at q = 0 moved by at most "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("JointKind::revolute_z,  // j3"), std::string::npos);
  EXPECT_NE(r.out.find("// Option: --snap 1e-05 (4 rotations and axes made exact)"),
            std::string::npos);
  // Every rotation entry of every placement is now exactly 0 or +-1. Each placement is written
  // as four lines, "{{{r00, r01, r02}," "{r10, r11, r12}," "{r20, r21, r22}}," "{px, py, pz}},".
  const auto begin = r.out.find("joint_placement = {{"), end = r.out.find("body_inertia");
  std::istringstream in(r.out.substr(begin, end - begin));
  std::vector<std::string> triples;
  for (std::string line; std::getline(in, line);) {
    const auto open = line.find_last_of('{');
    if (line.find("//") != std::string::npos || open == std::string::npos ||
        line.find('}', open) == std::string::npos)
      continue;
    triples.push_back(line.substr(open + 1, line.find('}', open) - open - 1));
  }
  int rows = 0;
  for (std::size_t t = 0; t < triples.size(); ++t) {
    if (t % 4 == 3)
      continue;  // the translation
    ++rows;
    std::istringstream cells(triples[t]);
    for (std::string cell; std::getline(cells, cell, ',');) {
      cell.erase(0, cell.find_first_not_of(' '));
      EXPECT_TRUE(cell == "0.0" || cell == "1.0" || cell == "-1.0") << triples[t];
    }
  }
  EXPECT_EQ(triples.size(), 12u);  // 3 placements x (3 rotation rows + 1 translation)
  EXPECT_EQ(rows, 9);
  const GenResult s = run("'" + kReal + "rounded_angles.urdf' --summary --snap 1e-5", dir);
  EXPECT_NE(s.out.find("  --snap 1e-05 made 4 exact: largest change 7.35e-06 rad;"),
            std::string::npos)
      << s.out;
  EXPECT_NE(s.out.find("  rotations and axes not axis-aligned: 0\n"), std::string::npos) << s.out;
}

TEST(GeneratorSummary, PrintsTheRobotTableWithoutWritingAHeader) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kRobots + "/kinova_gen3.urdf' --summary", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(files_in(dir), 0u);
  EXPECT_NE(r.out.find("robot 'GEN3-7DOF-VISION_ARM_URDF_V12' from kinova_gen3.urdf"),
            std::string::npos);
  EXPECT_NE(r.out.find("  bodies 7, DoF 7, operational frames 12, fixed base 'base_link'\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  joint kinds: RZ x7\n"), std::string::npos);
  // The URDF's joint_2 limits, velocity and effort; shoulder_link's mass.
  EXPECT_NE(r.out.find("    1  joint_2                half_arm_1_link          RZ        0    "
                       "-2.2400     2.2400       1.4        39    1.1636"),
            std::string::npos)
      << r.out;
  // The Kinova's rpy = 3.1416 and 1.5708: seven rotations within 1e-5 of axis-aligned.
  EXPECT_NE(r.out.find("rotations and axes not axis-aligned: 7; --snap TOL would make exact: "
                       "1e-09: 0, 1e-07: 0, 1e-06: 0, 1e-05: 7,"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  no warnings\n"), std::string::npos);
  const GenResult w = run("'" + kReal + "inertia_roundoff.urdf' --summary", dir);
  EXPECT_NE(w.out.find("  warning: link 'rod': inertia has a round-off negative principal"),
            std::string::npos)
      << w.out;
}

// ---- output properties -------------------------------------------------------------------
TEST(GeneratorOutput, DeterministicBytesAndBanner) {
  const fs::path dir = scratch();
  const GenResult a =
      run("'" + kRobots + "/iiwa7.urdf' -o '" + (dir / "a.hpp").string() + "'", dir);
  const GenResult b =
      run("'" + kRobots + "/iiwa7.urdf' -o '" + (dir / "b.hpp").string() + "'", dir);
  ASSERT_EQ(a.status, 0);
  ASSERT_EQ(b.status, 0);
  const std::string text = slurp(dir / "a.hpp");
  EXPECT_EQ(text, slurp(dir / "b.hpp"));
  // The checksum published with the robot files (shared/robots/README.md), not our own output.
  EXPECT_NE(text.find("760c0721572c6c3b9b73ff111ff2acce53c1ccd99ea310ffdc254fddddf5d63c"),
            std::string::npos);
  EXPECT_NE(text.find("from iiwa7.urdf"), std::string::npos);
  EXPECT_NE(text.find("arbor-gen 0."), std::string::npos);
  for (const char* word : {"2026", "2025", "UTC", ":00:"})
    EXPECT_EQ(text.find(word), std::string::npos) << "time stamp-like text: " << word;
}

TEST(GeneratorOutput, DefaultStructNameIsASanitizedRobotName) {
  const fs::path dir = scratch();
  const GenResult r = run("'" + kRobots + "/double_pendulum.urdf' -o -", dir);
  ASSERT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("struct Robot2dofPlanar {"), std::string::npos);
  EXPECT_NE(r.out.find("name = \"2dof_planar\";"), std::string::npos);
  const GenResult k = run("'" + kRobots + "/kinova_gen3.urdf' -o -", dir);
  ASSERT_EQ(k.status, 0);
  EXPECT_NE(k.out.find("struct GEN37DOFVISIONARMURDFV12 {"), std::string::npos);
}

TEST(GeneratorOutput, CreatesTheOutputFolder) {
  const fs::path dir = scratch();
  const fs::path header = dir / "deep" / "er" / "robot.hpp";
  ASSERT_EQ(run("'" + kData + "/merged.urdf' -o '" + header.string() + "'", dir).status, 0);
  EXPECT_TRUE(fs::exists(header));
}

#ifdef ARBOR_CLANG_FORMAT
// Outside the data tables (one entry per line, guarded with clang-format off), the header is
// exactly as clang-format with the project's style writes it.
TEST(GeneratorOutput, HeadersAreClangFormatClean) {
  const fs::path dir = scratch();
  for (const char* robot :
       {"double_pendulum", "iiwa7", "kinova_gen3", "yumi_no_grippers", "atlas"}) {
    const fs::path header = dir / (std::string(robot) + ".hpp");
    ASSERT_EQ(run("'" + kRobots + "/" + robot + ".urdf' -o '" + header.string() + "'", dir).status,
              0);
    const fs::path formatted = dir / "formatted.hpp";
    const std::string cmd = std::string("'") + ARBOR_CLANG_FORMAT + "' --style=file:'" +
                            ARBOR_SOURCE_DIR + "/.clang-format' '" + header.string() + "' > '" +
                            formatted.string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(slurp(header), slurp(formatted)) << robot;
  }
}
#endif

}  // namespace

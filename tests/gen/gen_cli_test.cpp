// arbor-gen as a user runs it: bad inputs give one clear message naming the file and the element,
// a non-zero exit and no output file; good inputs give deterministic headers.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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
                      BadCase{"floating.urdf", "floating joint 'free': floating joints are not"},
                      BadCase{"planar.urdf", "planar joint 'slide': planar joints are not"},
                      BadCase{"duplicate_link.urdf", "link 'a' is defined more than once"},
                      BadCase{"massless_subtree.urdf", "joint 'j1' moves no mass"},
                      BadCase{"no_movable.urdf", "no movable joint below root link 'base'"},
                      BadCase{"bad_inertia.urdf", "link 'a': inertia is not physical"},
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
        OptionCase{"--frobnicate", 2, "unknown option --frobnicate"}));

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
  EXPECT_EQ(r.out.find("gripper"), std::string::npos) << "gripper links must be dropped";
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

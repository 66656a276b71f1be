#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include <gtest/gtest.h>

#include "common/args.h"
#include "common/atomic_file.h"
#include "common/error.h"

namespace fs = std::filesystem;
using namespace irbake;

namespace {
fs::path scratch(const std::string& name) {
  fs::path dir = fs::current_path() / "test_scratch" / "common";
  fs::create_directories(dir);
  fs::path p = dir / name;
  fs::remove(p);
  return p;
}
// An empty folder of its own (scratch() would try to remove a non-empty one left by an earlier run).
fs::path scratchDir(const std::string& name) {
  fs::path dir = fs::current_path() / "test_scratch" / "common" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
size_t filesIn(const fs::path& dir) {
  size_t n = 0;
  for (auto& e : fs::directory_iterator(dir)) (void)e, ++n;
  return n;
}
}  // namespace

TEST(ArgParser, PositionalsOptionsAndFlags) {
  ArgParser p({"scene.gltf", "-o", "out", "--vpls=256", "--bias-compensation", "--clamp", "-0.5"},
              {"-o", "--vpls", "--clamp"}, {"--bias-compensation"});
  ASSERT_EQ(p.positionals().size(), 1u);
  EXPECT_EQ(p.positionals()[0], "scene.gltf");
  EXPECT_EQ(p.valueOr("-o", ""), "out");
  EXPECT_EQ(p.intOr("--vpls", 0), 256);
  EXPECT_DOUBLE_EQ(p.doubleOr("--clamp", 0.0), -0.5);
  EXPECT_TRUE(p.flag("--bias-compensation"));
  EXPECT_EQ(p.intOr("--missing", 7), 7);
}

TEST(ArgParser, RejectsUnknownOptionsAndBadNumbers) {
  try {
    ArgParser({"--nope"}, {}, {});
    FAIL() << "unknown option accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
    EXPECT_NE(std::string(e.what()).find("--nope"), std::string::npos);
  }
  ArgParser p({"--vpls", "12x", "--sun", "0,-1,nan,3"}, {"--vpls", "--sun"}, {});
  EXPECT_THROW(p.intOr("--vpls", 0), Error);
  EXPECT_THROW(p.numberList("--sun", 4), Error);
  ArgParser q({"--sun", "0,-1,0,3.5"}, {"--sun"}, {});
  auto v = q.numberList("--sun", 4);
  ASSERT_EQ(v.size(), 4u);
  EXPECT_DOUBLE_EQ(v[3], 3.5);
  EXPECT_THROW(q.numberList("--sun", 3), Error);
}

TEST(AtomicFile, WritesFinalNameOnlyOnSuccess) {
  fs::path p = scratch("ok.txt");
  writeAtomically(p, [](const fs::path& tmp) { std::ofstream(tmp) << "hello"; });
  ASSERT_TRUE(fs::exists(p));
  std::ifstream in(p);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "hello");
}

TEST(AtomicFile, FailureHalfWayLeavesNoFile) {
  fs::path dir = scratchDir("set");
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<PendingFile> files = {
      {dir / "a.bin", [](const fs::path& t) { std::ofstream(t) << "a"; }},
      {dir / "b.bin", [](const fs::path& t) {
         std::ofstream(t) << "partial";
         throw std::runtime_error("disk full");
       }},
  };
  EXPECT_THROW(writeAllAtomically(files), std::runtime_error);
  EXPECT_EQ(filesIn(dir), 0u) << "temp or final files left behind";
}

TEST(Error, MessageNamesFileAndExitCodesDiffer) {
  Error e(ErrorCode::InvalidData, "scene.gltf", "accessor 3 out of bounds");
  EXPECT_EQ(std::string(e.what()), "scene.gltf: accessor 3 out of bounds");
  std::set<int> codes;
  for (ErrorCode c : {ErrorCode::Io, ErrorCode::Parse, ErrorCode::InvalidData, ErrorCode::EmptyScene, ErrorCode::NoLight,
                      ErrorCode::Gl, ErrorCode::NumericError, ErrorCode::Usage}) {
    EXPECT_NE(exitCodeFor(c), 0);
    codes.insert(exitCodeFor(c));
  }
  EXPECT_EQ(codes.size(), 8u);
}

TEST(AtomicFile, RenameFailingHalfWayLeavesNoFile) {
  fs::path dir = scratchDir("rename");
  fs::create_directories(dir / "blocker");  // a non-empty folder where the second file should go
  std::ofstream(dir / "blocker" / "keep") << "x";
  std::vector<PendingFile> files = {
      {dir / "a.bin", [](const fs::path& t) { std::ofstream(t) << "a"; }},
      {dir / "blocker", [](const fs::path& t) { std::ofstream(t) << "b"; }},
  };
  EXPECT_THROW(writeAllAtomically(files), Error);
  EXPECT_FALSE(fs::exists(dir / "a.bin")) << "first file of a failed set left behind";
  EXPECT_EQ(filesIn(dir), 1u) << "temp files left behind";  // only the blocker folder
}

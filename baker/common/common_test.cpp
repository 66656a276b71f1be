#include <filesystem>
#include <functional>
#include <fstream>
#include <set>
#include <stdexcept>

#include <unistd.h>

#include <gtest/gtest.h>

#include "common/command_line.h"
#include "common/atomic_file.h"
#include "common/base64.h"
#include "common/error.h"
#include "common/excerpt.h"
#include "common/output_lock.h"

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

namespace {
// Parses args into a fresh app with the given setup; returns the Error(Usage) message, "" on success.
std::string parseError(const std::function<void(CLI::App&)>& setup, const std::vector<std::string>& args) {
  auto app = cli::makeApp("test", "test");
  setup(*app);
  try {
    cli::parse(*app, args);
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Usage);
    return e.what();
  }
  return "";
}
}  // namespace

TEST(CommandLine, PositionalsOptionsAndFlags) {
  std::vector<std::string> positionals;
  std::string out;
  int vpls = 0;
  double clamp = 0.0;
  bool flag = false;
  auto app = cli::makeApp("test", "test");
  app->add_option("SCENE", positionals);
  app->add_option("-o", out);
  app->add_option("--vpls", vpls)->transform(cli::integerIn(1, 1 << 26));
  app->add_option("--clamp", clamp)->transform(cli::numberIn(-1.0, 1.0));
  app->add_flag("--bias-compensation", flag);
  ASSERT_TRUE(cli::parse(*app, {"scene.gltf", "-o", "out", "--vpls=256", "--bias-compensation", "--clamp", "-0.5"}));
  ASSERT_EQ(positionals.size(), 1u);
  EXPECT_EQ(positionals[0], "scene.gltf");
  EXPECT_EQ(out, "out");
  EXPECT_EQ(vpls, 256);
  EXPECT_DOUBLE_EQ(clamp, -0.5);
  EXPECT_TRUE(flag);
}

TEST(CommandLine, IntegersOutsideTheirRangeAreRejectedNeverWrapped) {
  int value = 7;
  auto setup = [&](CLI::App& app) { app.add_option("--vpls", value)->transform(cli::integerIn(1, 1 << 26)); };
  // 2^32 + 1 wrapped to 1 and 2^31 to -2^31 through a cast to int: both must be refused as they are.
  for (const char* text : {"4294967297", "2147483648", "0", "-1", "12x", "", "1e3", "99999999999999999999999"}) {
    std::string message = parseError(setup, {"--vpls", text});
    EXPECT_NE(message.find("--vpls"), std::string::npos) << text << ": " << message;
    EXPECT_NE(message.find("must be an integer in [1, 67108864]"), std::string::npos) << text << ": " << message;
    EXPECT_EQ(value, 7) << text;
  }
  // Leading zeros are decimal (CLI11 alone would read "010" as octal 8).
  EXPECT_EQ(parseError(setup, {"--vpls", "010"}), "");
  EXPECT_EQ(value, 10);
  EXPECT_EQ(parseError(setup, {"--vpls", "67108864"}), "");
  EXPECT_EQ(value, 67108864);
}

TEST(CommandLine, AutoNumbersAndLists) {
  int bounces = 5;
  double tpu = 0.0;
  std::string sun;
  auto setup = [&](CLI::App& app) {
    app.add_option("--bounces", bounces)->transform(cli::integerOrAuto(0, 64, -1));
    app.add_option("--tpu", tpu)->transform(cli::numberIn(0.0, 1e6));
    app.add_option("--sun", sun)->transform(cli::numberList(4));
  };
  EXPECT_EQ(parseError(setup, {"--bounces", "auto"}), "");
  EXPECT_EQ(bounces, -1);
  EXPECT_EQ(parseError(setup, {"--bounces", "3"}), "");
  EXPECT_EQ(bounces, 3);
  EXPECT_NE(parseError(setup, {"--bounces", "65"}).find("'auto' or an integer in [0, 64]"), std::string::npos);
  EXPECT_NE(parseError(setup, {"--tpu", "nan"}).find("finite number in [0, 1000000]"), std::string::npos);
  EXPECT_NE(parseError(setup, {"--tpu", "2e6"}).find("got '2e6'"), std::string::npos);
  EXPECT_NE(parseError(setup, {"--sun", "0,-1,nan,3"}).find("'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(parseError(setup, {"--sun", "0,-1,0"}).find("needs 4 comma-separated numbers"), std::string::npos);
  EXPECT_EQ(parseError(setup, {"--sun", "0,-1,0,3.5"}), "");
  auto v = cli::parseNumberList(sun);
  ASSERT_EQ(v.size(), 4u);
  EXPECT_DOUBLE_EQ(v[1], -1.0);
  EXPECT_DOUBLE_EQ(v[3], 3.5);
  EXPECT_NE(parseError(setup, {"--nope"}).find("--nope"), std::string::npos);
}

TEST(CommandLine, HelpListsTheExitCodes) {
  const std::string help = exitCodeHelp();
  for (ErrorCode c : {ErrorCode::Usage, ErrorCode::Io, ErrorCode::Parse, ErrorCode::InvalidData, ErrorCode::EmptyScene,
                      ErrorCode::NoLight, ErrorCode::Gl, ErrorCode::NumericError})
    EXPECT_NE(help.find("  " + std::to_string(exitCodeFor(c)) + "  " + toString(c) + ":"), std::string::npos) << help;
  auto app = cli::makeApp("test", "test");
  EXPECT_NE(app->help().find(help), std::string::npos);
}

TEST(OutputFolderLock, SecondLockFailsAtOnceAndNothingIsLeftBehind) {
  fs::path dir = fs::current_path() / "test_scratch" / "common" / "locked_out";
  fs::remove_all(dir);
  {
    OutputFolderLock first(dir);
    EXPECT_TRUE(fs::exists(dir / OutputFolderLock::kFileName));
    // flock locks belong to the open file: a second lock in this process conflicts like another process.
    try {
      OutputFolderLock second(dir);
      FAIL() << "two locks on one folder";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Io);
      const std::string what = e.what();
      EXPECT_NE(what.find(dir.string()), std::string::npos) << what;
      EXPECT_NE(what.find("output folder is busy"), std::string::npos) << what;
      EXPECT_NE(what.find("process " + std::to_string(::getpid())), std::string::npos) << what;
    }
  }
  // Released: the folder this lock created was left empty, so it is gone; a new lock succeeds.
  EXPECT_FALSE(fs::exists(dir));
  fs::create_directories(dir);
  std::ofstream(dir / "kept.txt") << "x";
  { OutputFolderLock again(dir); }
  EXPECT_TRUE(fs::exists(dir / "kept.txt"));
  EXPECT_FALSE(fs::exists(dir / OutputFolderLock::kFileName));
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

// A user's text in a message: printable UTF-8 as it is, every other byte and the invisible marks escaped, a
// backslash doubled, long text cut with its size.
TEST(Excerpt, EscapesWhatDoesNotPrintAndCutsLongText) {
  EXPECT_EQ(quotedExcerpt("lamp"), "'lamp'");
  EXPECT_EQ(quotedExcerpt("gr\xC3\xB6\xC3\x9F" "e"), "'gr\xC3\xB6\xC3\x9F" "e'");  // größe
  EXPECT_EQ(quotedExcerpt(std::string("a\x01\0b\x7F", 5)), "'a\\x01\\x00b\\x7F'");
  EXPECT_EQ(quotedExcerpt("\xEF\xBB\xBFseed"), "'\\u{FEFF}seed'");
  EXPECT_EQ(quotedExcerpt("\xC2\x85 \xE2\x80\x8B"), "'\\u{0085} \\u{200B}'");
  EXPECT_EQ(quotedExcerpt("\xFF\xFE \xC0\xAF \xC3"), "'\\xFF\\xFE \\xC0\\xAF \\xC3'");  // invalid, overlong, cut
  EXPECT_EQ(quotedExcerpt("C:\\x41"), "'C:\\\\x41'");
  EXPECT_EQ(quotedExcerpt(std::string(100, 'x'), 10), "'xxxxxxxxxx…' (100 bytes)");
  EXPECT_EQ(printableExcerpt("C:\\dir \x1B[2J", 100), "C:\\dir \\x1B[2J");
  EXPECT_EQ(printableExcerpt(std::string(100, 'y'), 4), "yyyy… (100 bytes)");
}

// RFC 4648's test vectors, and every byte value through a round trip.
TEST(Base64, EncodesTheStandardVectorsAndRoundTripsEveryByte) {
  const char* const plain[] = {"", "f", "fo", "foo", "foob", "fooba", "foobar"};
  const char* const coded[] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(irbake::base64Encode(plain[i]), coded[i]);
    EXPECT_EQ(irbake::base64Decode(coded[i]), plain[i]);
  }
  std::string bytes;
  for (int b = 0; b < 256; ++b) bytes.push_back(static_cast<char>(b));
  EXPECT_EQ(irbake::base64Decode(irbake::base64Encode(bytes)), bytes);
  EXPECT_EQ(irbake::base64Decode("Zm9v\nYmFy"), "foobar");  // line breaks skipped
}

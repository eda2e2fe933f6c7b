// Where the control API may have captures written (orchestrator/fleet/capture_path.hpp; issue 32):
// inside the fleet's folders, never over a file, never out through a symbolic link.
#include "orchestrator/fleet/capture_path.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace canfleet::fleet {
namespace {

namespace fs = std::filesystem;

class CapturePath : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("canfleet-capture-path-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "state");
    fs::create_directories(root_ / "elsewhere");
    folders_ = {root_ / "state" / "captures", {root_ / "state" / "captures", root_ / "state"}};
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string Refusal(const std::string& requested) {
    try {
      ResolveCapturePath(requested, folders_);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  }

  fs::path root_;
  CaptureFolders folders_;
};

TEST_F(CapturePath, ARelativeFileGoesToTheCaptureFolderWhichIsMade) {
  const auto path = ResolveCapturePath("run/can0.pcap", folders_);
  EXPECT_EQ(path, fs::canonical(root_ / "state") / "captures" / "run" / "can0.pcap");
  EXPECT_TRUE(fs::is_directory(path.parent_path()));
}

TEST_F(CapturePath, AnAbsoluteFileInsideTheStateFolderIsTaken) {
  EXPECT_EQ(ResolveCapturePath((root_ / "state" / "x.log").string(), folders_),
            fs::canonical(root_ / "state") / "x.log");
}

TEST_F(CapturePath, AnythingOutsideIsRefusedWithTheReason) {
  for (const std::string& bad : {(root_ / "elsewhere" / "x.pcap").string(), std::string("/proc/self/mem"),
                                 std::string("/etc/passwd-new"), std::string("../../elsewhere/x.pcap"),
                                 (root_ / "state" / ".." / "elsewhere" / "x").string()}) {
    const auto why = Refusal(bad);
    EXPECT_NE(why.find("writes captures only inside"), std::string::npos) << bad << ": " << why;
  }
  EXPECT_FALSE(fs::exists(root_ / "elsewhere" / "x.pcap"));
}

TEST_F(CapturePath, AnExistingFileIsNeverReplaced) {
  std::ofstream(root_ / "state" / "params.bin") << "stored parameters";
  EXPECT_NE(Refusal((root_ / "state" / "params.bin").string()).find("exists"), std::string::npos);
  std::ifstream in(root_ / "state" / "params.bin");
  std::string content;
  std::getline(in, content);
  EXPECT_EQ(content, "stored parameters");
}

TEST_F(CapturePath, ASymbolicLinkDoesNotLeadOut) {
  fs::create_directory_symlink(root_ / "elsewhere", root_ / "state" / "out");
  EXPECT_NE(Refusal((root_ / "state" / "out" / "x.pcap").string()).find("only inside"), std::string::npos);
  fs::create_symlink(root_ / "elsewhere" / "target", root_ / "state" / "link.pcap");
  EXPECT_NE(Refusal((root_ / "state" / "link.pcap").string()), "accepted");
  EXPECT_FALSE(fs::exists(root_ / "elsewhere" / "target"));
}

TEST_F(CapturePath, EmptyOrAFolderIsRefused) {
  EXPECT_NE(Refusal("").find("needs a file"), std::string::npos);
  EXPECT_NE(Refusal(".").find("names a folder"), std::string::npos);
  EXPECT_NE(Refusal("sub/..").find("names a folder"), std::string::npos);
}

}  // namespace
}  // namespace canfleet::fleet

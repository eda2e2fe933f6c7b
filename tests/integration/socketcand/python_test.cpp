// python-can (interface='socketcand', an off-the-shelf client nobody here wrote) on the endpoint,
// over real TCP: frames the script sends reach a C++ port of the bus, and frames the C++ port
// sends reach the script, with identifiers, formats, data and order intact (issue 4: "python-can
// sends and receives through the socketcand endpoint"). Integration tier: a Python process, real TCP.
//
// The interpreter is the project's venv (scripts/python-env.sh, pinned python-can), or
// $CANFLEET_SOCKETCAND_PYTHON to try another one (e.g. a venv with Debian's python-can 4.1.0).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "tests/integration/socketcand/tcp_endpoint.hpp"

namespace canfleet::socketcand {
namespace {

using namespace std::chrono_literals;
using test::Endpoint;

/// The frames of python_socketcand_client.py's frame(i).
CanFrame PyFrame(int i) {
  const bool extended = i % 3 == 2;
  CanFrame f;
  if (i % 7 == 5) {
    f.id = 0x123;
  } else if (extended) {
    f.id = 0x1ABC0000u + static_cast<std::uint32_t>(i);
  } else {
    f.id = 0x100u + static_cast<std::uint32_t>(i % 0x600);
  }
  if (extended) f.flags |= CanFrame::kExtended;
  f.dlc = static_cast<std::uint8_t>(i % 9);
  for (int k = 0; k < f.dlc; ++k)
    f.data[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>((i + k * 17) & 0xFF);
  return f;
}

std::string Shell(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) {
    status = -1;
    return out;
  }
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe) != nullptr)
    out += buf;
  status = ::pclose(pipe);
  return out;
}

/// The interpreter to use, or an empty string with the reason in `why` (PyPI not reachable:
/// skipped). Any other failure of the venv is a test failure: it is the project's, not the machine's.
std::string Python(std::string& why) {
  if (const char* forced = std::getenv("CANFLEET_SOCKETCAND_PYTHON")) return forced;
  int status = 0;
  std::string out = Shell(std::string(CANFLEET_SOURCE_DIR) + "/scripts/python-env.sh 2>&1", status);
  if (status != 0) {
    const bool no_pypi = WIFEXITED(status) && WEXITSTATUS(status) == 75;
    if (!no_pypi) ADD_FAILURE() << "scripts/python-env.sh failed (exit " << status << "):\n" << out;
    why = "scripts/python-env.sh could not provide python-can (PyPI not reachable):\n" + out;
    return {};
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r'))
    out.pop_back();
  return out.substr(out.rfind('\n') + 1);  // the last line is the interpreter's path
}

struct Rx {
  CanFrame frame;
  double timestamp = 0;
};

Rx ParseRx(const std::string& line) {
  std::istringstream in(line.substr(3));
  std::string id, data;
  int extended = 0, dlc = 0;
  Rx rx;
  in >> id >> extended >> dlc >> data >> rx.timestamp;
  rx.frame.id = static_cast<std::uint32_t>(std::stoul(id, nullptr, 16));
  if (extended != 0) rx.frame.flags |= CanFrame::kExtended;
  rx.frame.dlc = static_cast<std::uint8_t>(dlc);
  if (data == "-") data.clear();
  for (std::size_t k = 0; 2 * k + 1 < data.size(); ++k)
    rx.frame.data[k] = static_cast<std::uint8_t>(std::stoul(data.substr(2 * k, 2), nullptr, 16));
  return rx;
}

TEST(PythonCan, SendsAndReceivesThroughTheSocketcandEndpoint) {
  std::string why;
  const std::string python = Python(why);
  if (python.empty()) GTEST_SKIP() << why;

  constexpr int kFromPython = 1000;
  constexpr int kFromCpp = 1500;  // ~96 kB of records: many 1024-byte reads on the client side
  Endpoint ep({}, {.name = "can0", .bitrate = 1'000'000, .tx_queue_capacity = 4096});

  const std::string command = python + " " + CANFLEET_SOURCE_DIR +
                              "/tests/integration/socketcand/python_socketcand_client.py --port " +
                              std::to_string(ep.port()) + " --channel can0 --send " +
                              std::to_string(kFromPython) + " --receive " + std::to_string(kFromCpp) +
                              " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::vector<Rx> received;
  std::string version, transcript;
  char line[512];
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    std::string text(line);
    if (!text.empty() && text.back() == '\n') text.pop_back();
    if (text.rfind("RX ", 0) == 0) {
      received.push_back(ParseRx(text));
      continue;
    }
    transcript += text + "\n";
    if (text.rfind("VERSION ", 0) == 0) version = text.substr(8);
    if (text == "READY") {
      std::vector<CanFrame> frames;
      for (int i = 0; i < kFromCpp; ++i)
        frames.push_back(PyFrame(i));
      ep.Send(frames);
    }
  }
  const int status = ::pclose(pipe);
  EXPECT_EQ(status, 0) << transcript;

  // python-can before 4.2 (Debian 12 has 4.1.0) writes 29-bit ids without leading zeros, so a
  // small one arrives as an 11-bit id, and marks every received frame extended.
  const bool legacy = version.rfind("4.0.", 0) == 0 || version.rfind("4.1.", 0) == 0;

  // Python → C++: every frame, in the order sent.
  const std::vector<CanFrame> got = ep.WaitReceived(kFromPython);
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kFromPython)) << transcript;
  for (int i = 0; i < kFromPython; ++i) {
    CanFrame expected = PyFrame(i);
    if (legacy && expected.id <= CanFrame::kMaxStandardId)
      expected.flags &= static_cast<std::uint8_t>(~CanFrame::kExtended);
    ASSERT_EQ(ToCandump(got[static_cast<std::size_t>(i)]), ToCandump(expected)) << "frame " << i;
  }

  // C++ → Python: every frame, in order, with wall-clock timestamps.
  ASSERT_EQ(received.size(), static_cast<std::size_t>(kFromCpp)) << transcript;
  const bool extended_flag_reliable = !legacy;
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  for (int i = 0; i < kFromCpp; ++i) {
    CanFrame expected = PyFrame(i);
    CanFrame actual = received[static_cast<std::size_t>(i)].frame;
    if (!extended_flag_reliable) {
      expected.flags &= static_cast<std::uint8_t>(~CanFrame::kExtended);
      actual.flags &= static_cast<std::uint8_t>(~CanFrame::kExtended);
    }
    ASSERT_EQ(ToCandump(actual), ToCandump(expected)) << "frame " << i << " (python-can " << version << ")";
    if (i > 0) {
      EXPECT_GE(received[static_cast<std::size_t>(i)].timestamp,
                received[static_cast<std::size_t>(i - 1)].timestamp);
    }
  }
  EXPECT_NEAR(received.back().timestamp, now, 60.0) << "timestamps are wall-clock time";
  EXPECT_EQ(ep.Stats().output_drops, 0u);
  std::printf("python-can %s: %d frames sent, %d received\n", version.c_str(), kFromPython, kFromCpp);
}

}  // namespace
}  // namespace canfleet::socketcand

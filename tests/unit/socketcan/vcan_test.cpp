// SocketCanPort and SocketCanBridge on a real vcan0, side by side with raw sockets and can-utils.
// Needs a kernel with CAN: scripts/vm-can-test.sh runs this binary in a VM (ctest label `vm`).
// Run directly on a host without vcan0, every test is skipped with the reason; with
// CANFLEET_VCAN set (the VM script sets it) a missing interface is a failure instead.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "bus/loopback_bus.hpp"
#include "bus/socketcan/socketcan_bridge.hpp"
#include "bus/socketcan/socketcan_port.hpp"

extern char** environ;

namespace canfleet {
namespace {

using namespace std::chrono_literals;

std::string Interface() {
  const char* name = std::getenv("CANFLEET_VCAN");
  return name != nullptr && *name != '\0' ? name : "vcan0";
}
bool InterfaceRequired() {
  return std::getenv("CANFLEET_VCAN") != nullptr;
}

/// A plain raw socket, the way candump and cansend use SocketCAN: the independent observer.
class RawCan {
 public:
  explicit RawCan(const std::string& interface, can_err_mask_t error_mask = 0) {
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) throw std::runtime_error("socket(PF_CAN): " + std::string(std::strerror(errno)));
    ifreq request{};
    std::strncpy(request.ifr_name, interface.c_str(), IFNAMSIZ - 1);
    if (::ioctl(fd_, SIOCGIFINDEX, &request) != 0) Fail(interface + ": " + std::strerror(errno));
    ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof error_mask);
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = request.ifr_ifindex;
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      Fail("bind: " + std::string(std::strerror(errno)));
    }
  }
  ~RawCan() { ::close(fd_); }
  RawCan(const RawCan&) = delete;
  RawCan& operator=(const RawCan&) = delete;

  void Write(const can_frame& frame) {
    ASSERT_EQ(::write(fd_, &frame, sizeof frame), static_cast<ssize_t>(sizeof frame)) << std::strerror(errno);
  }
  void Write(const CanFrame& frame) { Write(ToKernelFrame(frame)); }

  std::optional<can_frame> ReadKernel(std::chrono::milliseconds timeout) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) != 1) return std::nullopt;
    can_frame frame{};
    if (::read(fd_, &frame, sizeof frame) != static_cast<ssize_t>(sizeof frame)) return std::nullopt;
    return frame;
  }
  /// The next frame in candump's compact form, or "" after the timeout.
  std::string Read(std::chrono::milliseconds timeout = 2s) {
    auto frame = ReadKernel(timeout);
    if (!frame) return "";
    auto decoded = FromKernelFrame(*frame);
    return decoded ? ToCandump(*decoded) : "malformed";
  }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    ::close(fd_);
    throw std::runtime_error(what);
  }
  int fd_ = -1;
};

template <class Predicate>
bool RunUntil(asio::io_context& io, Predicate done, std::chrono::milliseconds limit = 3s) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    io.restart();
    io.run_for(5ms);
  }
  return true;
}

void RunFor(asio::io_context& io, std::chrono::milliseconds duration) {
  io.restart();
  io.run_for(duration);
}

can_frame ErrorFrame(canid_t error_class, std::uint8_t controller_status = 0) {
  can_frame frame{};
  frame.can_id = CAN_ERR_FLAG | error_class;
  frame.len = CAN_ERR_DLC;
  frame.data[1] = controller_status;
  return frame;
}

/// Collects what a BusPort receives, in candump form.
struct Received {
  std::vector<std::string> frames;
  std::vector<BusTime> times;
  void Attach(BusPort& port) {
    port.OnReceive([this](const CanFrame& frame, BusTime time) {
      frames.push_back(ToCandump(frame));
      times.push_back(time);
    });
  }
};

class Vcan : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      RawCan probe(Interface());
    } catch (const std::exception& e) {
      if (InterfaceRequired()) {
        FAIL() << "CANFLEET_VCAN is set but " << Interface() << " cannot be used: " << e.what();
      }
      GTEST_SKIP() << Interface() << " is not available here (" << e.what()
                   << "); scripts/vm-can-test.sh runs this test in a VM";
    }
  }
  asio::io_context io_;
};

TEST_F(Vcan, PortFramesAreSeenByARawSocketBitForBit) {
  RawCan observer(Interface());
  SocketCanPort port(io_, Interface());
  CanFrame extended = CanFrame::Data(0x1ABCDEF0, {0x01});
  extended.flags = CanFrame::kExtended;
  ASSERT_TRUE(port.Send(CanFrame::Data(0x123, {0xDE, 0xAD, 0xBE, 0xEF})));
  ASSERT_TRUE(port.Send(extended));
  ASSERT_TRUE(port.Send(CanFrame::Remote(0x7FF, 2)));
  ASSERT_TRUE(RunUntil(io_, [&] { return port.Stats().tx_frames == 3; }));

  auto a = observer.ReadKernel(2s), b = observer.ReadKernel(2s), c = observer.ReadKernel(2s);
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->can_id, 0x123u);
  EXPECT_EQ(a->len, 4);
  EXPECT_EQ(std::vector<std::uint8_t>(a->data, a->data + 4),
            (std::vector<std::uint8_t>{0xDE, 0xAD, 0xBE, 0xEF}));
  EXPECT_EQ(b->can_id, CAN_EFF_FLAG | 0x1ABCDEF0u);
  EXPECT_EQ(b->len, 1);
  EXPECT_EQ(c->can_id, CAN_RTR_FLAG | 0x7FFu);
  EXPECT_EQ(c->len, 2);
  EXPECT_EQ(port.Stats().tx_batches, 1u) << "three frames queued in one turn go out in one sendmmsg";
  EXPECT_EQ(observer.Read(100ms), "") << "nothing else on the bus";
}

TEST_F(Vcan, RawSocketFramesReachThePortInOrderInBatches) {
  RawCan sender(Interface());
  SocketCanPort port(io_, Interface());
  Received got;
  got.Attach(port);
  std::vector<std::string> sent;
  for (int chunk = 0; chunk < 20; ++chunk) {
    for (int i = 0; i < 50; ++i) {
      const int n = chunk * 50 + i;
      auto frame = CanFrame::Data(static_cast<std::uint32_t>(0x100 + n % 0x600),
                                  {static_cast<std::uint8_t>(n >> 8), static_cast<std::uint8_t>(n)});
      sender.Write(frame);
      sent.push_back(ToCandump(frame));
    }
    RunFor(io_, 1ms);  // let the port drain between chunks, as a live bus would
  }
  ASSERT_TRUE(RunUntil(io_, [&] { return got.frames.size() >= sent.size(); })) << got.frames.size();
  EXPECT_EQ(got.frames, sent);
  EXPECT_LT(port.Stats().rx_batches, 200u) << "recvmmsg should return many frames per call";
  for (std::size_t i = 0; i < got.times.size(); ++i) {
    ASSERT_GT(got.times[i].count(), 0) << "kernel receive time missing";
    if (i > 0) {
      ASSERT_GE(got.times[i], got.times[i - 1]);
    }
  }
}

TEST_F(Vcan, APortNeverHearsItselfButOtherPortsDo) {
  SocketCanPort a(io_, Interface()), b(io_, Interface());
  Received at_a, at_b;
  at_a.Attach(a);
  at_b.Attach(b);
  ASSERT_TRUE(a.Send(CanFrame::Data(0x181, {0x11})));
  ASSERT_TRUE(b.Send(CanFrame::Data(0x182, {0x22})));
  ASSERT_TRUE(RunUntil(io_, [&] { return !at_a.frames.empty() && !at_b.frames.empty(); }));
  RunFor(io_, 50ms);
  EXPECT_EQ(at_a.frames, std::vector<std::string>{"182#22"});
  EXPECT_EQ(at_b.frames, std::vector<std::string>{"181#11"});
}

TEST_F(Vcan, ErrorFramesDriveTheControllerState) {
  RawCan injector(Interface());
  SocketCanPort port(io_, Interface());
  SocketCanPortOptions with_errors;
  with_errors.deliver_error_frames = true;
  SocketCanPort watcher(io_, Interface(), with_errors);
  std::vector<ControllerEvent> events;
  port.OnStateChange([&](const ControllerEvent& e) { events.push_back(e); });
  Received data, errors;
  data.Attach(port);
  errors.Attach(watcher);

  injector.Write(ErrorFrame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE));
  ASSERT_TRUE(RunUntil(io_, [&] { return events.size() == 1; }));
  EXPECT_EQ(events[0].state, ControllerState::kErrorPassive);
  EXPECT_EQ(port.State(), ControllerState::kErrorPassive);

  injector.Write(ErrorFrame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE));  // still passive: no event
  injector.Write(ErrorFrame(CAN_ERR_BUSOFF));
  ASSERT_TRUE(RunUntil(io_, [&] { return events.size() == 2; }));
  EXPECT_EQ(events[1].state, ControllerState::kBusOff);
  EXPECT_FALSE(port.Send(CanFrame::Data(0x181, {1}))) << "a bus-off controller does not transmit";

  injector.Write(ErrorFrame(CAN_ERR_RESTARTED));
  ASSERT_TRUE(RunUntil(io_, [&] { return events.size() == 3; }));
  EXPECT_EQ(events[2].state, ControllerState::kErrorActive);
  EXPECT_TRUE(port.Send(CanFrame::Data(0x181, {1})));

  ASSERT_TRUE(RunUntil(io_, [&] { return errors.frames.size() == 4; })) << errors.frames.size();
  EXPECT_TRUE(data.frames.empty()) << "error frames are not data";
  EXPECT_EQ(port.Stats().rx_error_frames, 4u);
}

TEST_F(Vcan, BridgeJoinsALoopbackBusAndVcanWithoutEchoes) {
  RawCan tool(Interface());  // stands for candump/cansend on the Linux side
  LoopbackBus bus;
  SocketCanBridge bridge(io_, Interface());
  bridge.ConnectTo(bus.Attach("bridge"));
  auto& node = bus.Attach("node");
  Received at_node;
  at_node.Attach(node);

  // virtual bus -> SocketCAN
  ASSERT_TRUE(node.Send(CanFrame::Data(0x181, {1, 2, 3})));
  RunFor(io_, 5ms);
  EXPECT_EQ(tool.Read(), "181#010203");

  // SocketCAN -> virtual bus
  tool.Write(CanFrame::Data(0x201, {0xAA}));
  ASSERT_TRUE(RunUntil(io_, [&] { return !at_node.frames.empty(); }));
  EXPECT_EQ(at_node.frames, std::vector<std::string>{"201#AA"});

  RunFor(io_, 50ms);
  EXPECT_EQ(tool.Read(100ms), "") << "the bridge wrote 201#AA back to the interface";
  ASSERT_EQ(bus.History().size(), 2u) << "a frame crossed back onto the virtual bus";
  EXPECT_EQ(ToCandump(bus.History()[0]), "181#010203");
  EXPECT_EQ(ToCandump(bus.History()[1]), "201#AA");
  EXPECT_EQ(bridge.BridgeStats().to_virtual_bus, 1u);
  EXPECT_EQ(bridge.BridgeStats().to_socketcan, 1u);
}

TEST_F(Vcan, BridgeWithASinkAndAPortOnTheSameInterface) {
  std::vector<std::string> sunk;
  SocketCanBridge bridge(io_, Interface(), [&](std::span<const CanFrame> frames) {
    for (const auto& f : frames)
      sunk.push_back(ToCandump(f));
  });
  SocketCanPort port(io_, Interface());
  Received at_port;
  at_port.Attach(port);

  ASSERT_TRUE(port.Send(CanFrame::Data(0x300, {0x01})));
  ASSERT_TRUE(RunUntil(io_, [&] { return !sunk.empty(); }));
  EXPECT_EQ(sunk, std::vector<std::string>{"300#01"});

  CanFrame error;
  error.flags = CanFrame::kError;
  error.id = CAN_ERR_BUSOFF;
  error.dlc = 8;
  const std::vector<CanFrame> from_virtual{CanFrame::Data(0x301, {0x02}), error,
                                           CanFrame::Data(0x302, {0x03})};
  EXPECT_EQ(bridge.FromVirtualBus(from_virtual), 2u);
  ASSERT_TRUE(RunUntil(io_, [&] { return at_port.frames.size() == 2; }));
  EXPECT_EQ(at_port.frames, (std::vector<std::string>{"301#02", "302#03"}));
  RunFor(io_, 50ms);
  EXPECT_EQ(sunk, std::vector<std::string>{"300#01"}) << "what the bridge wrote came back to its sink";
  EXPECT_EQ(bridge.BridgeStats().dropped, 1u) << "the error frame must not be transmitted";
  EXPECT_EQ(bridge.SocketCanState(), ControllerState::kErrorActive);
}

TEST_F(Vcan, APortMayBeDestroyedFromItsHandlerOrWithFramesQueued) {
  RawCan sender(Interface());
  auto port = std::make_unique<SocketCanPort>(io_, Interface());
  int calls = 0;
  port->OnReceive([&](const CanFrame&, BusTime) {
    ++calls;
    port.reset();  // the rest of the batch must not be delivered to a dead port
  });
  for (int i = 0; i < 10; ++i)
    sender.Write(CanFrame::Data(0x100, {static_cast<std::uint8_t>(i)}));
  ASSERT_TRUE(RunUntil(io_, [&] { return port == nullptr; }));
  RunFor(io_, 20ms);
  EXPECT_EQ(calls, 1);

  auto queued = std::make_unique<SocketCanPort>(io_, Interface());
  ASSERT_TRUE(queued->Send(CanFrame::Data(0x101, {1})));  // flush posted, not yet run
  queued.reset();
  RunFor(io_, 20ms);  // the posted flush finds the port gone (ASan would object otherwise)
  EXPECT_EQ(sender.Read(100ms), "");
}

TEST_F(Vcan, NonCanInterfaceIsRefusedClearly) {
  asio::io_context io;
  try {
    SocketCanPort port(io, "lo");
    FAIL() << "bound a CAN socket to lo";
  } catch (const SocketCanError& e) {
    EXPECT_STREQ(e.what(), "socketcan: lo: No such device (not a CAN interface)");
  }
}

/// Runs a shell command; true when it exits 0.
bool Shell(const std::string& command) {
  return std::system((command + " >/dev/null 2>&1").c_str()) == 0;
}

TEST_F(Vcan, InterfaceDownAndDeletedAreReportedNotFatal) {
  const std::string name = "cfvcan9";
  Shell("ip link delete dev " + name);
  if (!Shell("ip link add dev " + name + " type vcan")) {
    if (InterfaceRequired()) {
      FAIL() << "cannot create " << name << " (root is needed)";
    }
    GTEST_SKIP() << "cannot create " << name << " here (root is needed)";
  }
  try {
    SocketCanPort down(io_, name);
    ADD_FAILURE() << "opened an interface that is down";
  } catch (const SocketCanError& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "socketcan: " + name + ": Network is down (the interface is down: ip link set up " + name + ")");
  }
  ASSERT_TRUE(Shell("ip link set up " + name));
  SocketCanPort port(io_, name);
  std::vector<std::error_code> errors;
  port.OnError([&](std::error_code e) { errors.push_back(e); });

  ASSERT_TRUE(Shell("ip link set down " + name));
  ASSERT_TRUE(RunUntil(io_, [&] { return !errors.empty(); })) << "no error after the interface went down";
  EXPECT_EQ(errors[0], std::errc::network_down) << errors[0].message();

  EXPECT_TRUE(port.Send(CanFrame::Data(0x123, {1})));  // queued; the kernel refuses it
  ASSERT_TRUE(RunUntil(io_, [&] { return port.Stats().tx_failed == 1; }));
  EXPECT_EQ(port.Stats().tx_frames, 0u);

  ASSERT_TRUE(Shell("ip link delete dev " + name));
  const auto before = errors.size();
  ASSERT_TRUE(RunUntil(io_, [&] { return errors.size() > before; }))
      << "no error after the interface was deleted";
  EXPECT_EQ(errors.back(), std::errc::no_such_device) << errors.back().message();
  RunFor(io_, 50ms);  // and the port does not spin on the dead socket
  EXPECT_LT(port.Stats().io_errors, 10u);
}

// --- can-utils interoperate with the port -----------------------------------------------------

/// A child process with its stdout on a pipe.
class Child {
 public:
  explicit Child(std::vector<std::string> argv) {
    int pipe_fds[2];
    if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe2");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
    std::vector<char*> args;
    for (auto& a : argv)
      args.push_back(a.data());
    args.push_back(nullptr);
    const int rc = ::posix_spawnp(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(pipe_fds[1]);
    out_ = pipe_fds[0];
    if (rc != 0) {
      ::close(out_);
      throw std::runtime_error(argv[0] + ": " + std::strerror(rc));
    }
    ::fcntl(out_, F_SETFL, O_NONBLOCK);
  }
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      Wait();
    }
    ::close(out_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// Complete output lines so far.
  std::vector<std::string> Lines() {
    char buffer[4096];
    ssize_t n;
    while ((n = ::read(out_, buffer, sizeof buffer)) > 0)
      text_.append(buffer, static_cast<std::size_t>(n));
    std::vector<std::string> lines;
    std::size_t start = 0, end;
    while ((end = text_.find('\n', start)) != std::string::npos) {
      lines.push_back(text_.substr(start, end - start));
      start = end + 1;
    }
    return lines;
  }
  int Wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  std::string text_;
};

bool HaveCanUtils() {
  return std::system("command -v cansend >/dev/null && command -v candump >/dev/null") == 0;
}

class CanUtils : public Vcan {
 protected:
  void SetUp() override {
    Vcan::SetUp();
    if (IsSkipped() || HasFatalFailure()) return;
    if (!HaveCanUtils()) {
      if (InterfaceRequired()) {
        FAIL() << "can-utils (cansend, candump) are not installed";
      }
      GTEST_SKIP() << "can-utils are not installed";
    }
  }
};

TEST_F(CanUtils, CansendReachesThePort) {
  SocketCanPort port(io_, Interface());
  Received got;
  got.Attach(port);
  for (const char* frame : {"123#DEADBEEF", "1F334455#R", "7FF#"}) {
    Child cansend({"cansend", Interface(), frame});
    ASSERT_EQ(cansend.Wait(), 0) << "cansend " << frame;
  }
  ASSERT_TRUE(RunUntil(io_, [&] { return got.frames.size() == 3; })) << got.frames.size();
  EXPECT_EQ(got.frames, (std::vector<std::string>{"123#DEADBEEF", "1F334455#R", "7FF#"}));
}

TEST_F(CanUtils, CandumpSeesThePortsFrames) {
  SocketCanPort port(io_, Interface());
  Child candump({"candump", "-L", Interface()});
  // candump binds at some point after it starts: send a marker until it shows up, then the frames.
  const std::string marker = "7E0#00";
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  auto seen_marker = [&] {
    for (const auto& line : candump.Lines()) {
      if (line.find(marker) != std::string::npos) return true;
    }
    return false;
  };
  while (!seen_marker()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "candump printed nothing";
    port.Send(CanFrame::Data(0x7E0, {0x00}));
    RunFor(io_, 50ms);
  }
  CanFrame extended = CanFrame::Data(0x1ABCDEF0, {0x01, 0x02});
  extended.flags = CanFrame::kExtended;
  const std::vector<CanFrame> frames{CanFrame::Data(0x123, {0xDE, 0xAD, 0xBE, 0xEF}), extended,
                                     CanFrame::Remote(0x7FF, 0)};
  for (const auto& f : frames)
    ASSERT_TRUE(port.Send(f));
  std::vector<std::string> dumped;
  ASSERT_TRUE(RunUntil(
      io_,
      [&] {
        dumped.clear();
        for (const auto& line : candump.Lines()) {
          if (line.find(marker) == std::string::npos) dumped.push_back(line);
        }
        return dumped.size() >= frames.size();
      },
      5s));
  // candump -L: "(seconds.micros) vcan0 123#DEADBEEF"
  ASSERT_EQ(dumped.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::string expected = " " + Interface() + " " + ToCandump(frames[i]);
    EXPECT_TRUE(dumped[i].size() > expected.size() &&
                dumped[i].compare(dumped[i].size() - expected.size(), expected.size(), expected) == 0)
        << dumped[i] << " should end with" << expected;
  }
}

}  // namespace
}  // namespace canfleet

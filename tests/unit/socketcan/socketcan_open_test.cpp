// Opening SocketCAN must fail with a message that says why (CONTRIBUTING: exceptions at the
// edges). Runs on any host: the expected reason depends on what the kernel offers.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <string>

#include "bus/socketcan/socketcan_bridge.hpp"
#include "bus/socketcan/socketcan_port.hpp"

namespace canfleet {
namespace {

bool KernelHasCan() {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd >= 0) ::close(fd);
  return fd >= 0;
}

std::string OpenError(const std::string& interface) {
  asio::io_context io;
  try {
    SocketCanPort port(io, interface);
  } catch (const SocketCanError& e) {
    return e.what();
  }
  return "";
}

TEST(SocketCanOpen, MissingInterfaceOrMissingCanSupportIsExplained) {
  const std::string message = OpenError("cfnx0");
  if (KernelHasCan()) {
    EXPECT_EQ(
        message.rfind("socketcan: cfnx0: No such device (no such network interface; a virtual one is made "
                      "with `ip link add dev cfnx0 type vcan && ip link set up cfnx0`)",
                      0),
        0u)
        << message;
  } else {
    EXPECT_EQ(message,
              "socketcan: cfnx0: Address family not supported by protocol (the kernel has no CAN support)");
  }
}

TEST(SocketCanOpen, Vcan0OnAKernelWithoutCanSaysSo) {
  if (KernelHasCan()) GTEST_SKIP() << "this kernel has CAN: the VM test (label vm) covers vcan0";
  EXPECT_EQ(OpenError("vcan0"),
            "socketcan: vcan0: Address family not supported by protocol (the kernel has no CAN support)");
}

TEST(SocketCanOpen, ErrorCarriesTheErrno) {
  asio::io_context io;
  try {
    SocketCanBridge bridge(io, "cfnx0");
    FAIL() << "opened a missing interface";
  } catch (const SocketCanError& e) {
    EXPECT_TRUE(e.code() == std::errc::no_such_device || e.code() == std::errc::address_family_not_supported)
        << e.code().message();
  }
}

TEST(SocketCanOpen, OverlongOrEmptyNamesAreRefusedBeforeTheKernelIsAsked) {
  EXPECT_EQ(OpenError("a-name-longer-than-15"),
            "socketcan: a-name-longer-than-15: Invalid argument (an interface name has 1 to 15 characters)");
  EXPECT_EQ(OpenError(""), "socketcan: : Invalid argument (an interface name has 1 to 15 characters)");
}

}  // namespace
}  // namespace canfleet

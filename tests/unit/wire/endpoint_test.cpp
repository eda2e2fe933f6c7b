// Endpoint syntax of the broker client and the broker's --listen (issue 4: TCP and Unix-domain
// sockets; loopback by default, other addresses only when asked for explicitly).
#include <gtest/gtest.h>

#include <stdexcept>

#include "bus/wire/endpoint.hpp"

namespace canfleet::wire {
namespace {

TEST(Endpoint, ParsesTcp) {
  const Endpoint ep = Endpoint::Parse("tcp://127.0.0.1:29600");
  EXPECT_EQ(ep.kind, Endpoint::Kind::kTcp);
  EXPECT_EQ(ep.host, "127.0.0.1");
  EXPECT_EQ(ep.port, 29600);
  EXPECT_TRUE(ep.IsLoopback());
  EXPECT_EQ(ep.ToString(), "tcp://127.0.0.1:29600");
}

TEST(Endpoint, ParsesIpv6AndNames) {
  const Endpoint v6 = Endpoint::Parse("tcp://[::1]:0");
  EXPECT_EQ(v6.host, "::1");
  EXPECT_EQ(v6.port, 0);
  EXPECT_TRUE(v6.IsLoopback());
  EXPECT_EQ(v6.ToString(), "tcp://[::1]:0");
  EXPECT_TRUE(Endpoint::Parse("tcp://localhost:1").IsLoopback());
  EXPECT_FALSE(Endpoint::Parse("tcp://0.0.0.0:29600").IsLoopback());
  EXPECT_FALSE(Endpoint::Parse("tcp://broker.example:29600").IsLoopback());
}

TEST(Endpoint, ParsesUnix) {
  const Endpoint ep = Endpoint::Parse("unix:///tmp/canfleet/broker.sock");
  EXPECT_EQ(ep.kind, Endpoint::Kind::kUnix);
  EXPECT_EQ(ep.path, "/tmp/canfleet/broker.sock");
  EXPECT_EQ(ep.ToString(), "unix:///tmp/canfleet/broker.sock");
  EXPECT_EQ(Endpoint::Parse("unix://rel.sock").path, "rel.sock");
  EXPECT_FALSE(ep.IsLoopback());
}

TEST(Endpoint, RejectsMalformedText) {
  for (const char* text :
       {"", "127.0.0.1:29600", "http://x:1", "tcp://", "tcp://host", "tcp://:1", "tcp://h:", "tcp://h:65536",
        "tcp://h:-1", "tcp://h:1x", "tcp://::1:5", "tcp://[::1]5", "tcp://[::1:5", "unix://"}) {
    EXPECT_THROW(Endpoint::Parse(text), std::invalid_argument) << text;
  }
  EXPECT_THROW(Endpoint::Parse("unix:///" + std::string(200, 'a')), std::invalid_argument);
  try {
    Endpoint::Parse("tcp://host");
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "endpoint \"tcp://host\": missing :port (expected tcp://host:port or unix:///path)");
  }
}

}  // namespace
}  // namespace canfleet::wire

// canfleet web --listen: [ADDRESS:]PORT, and which addresses count as loopback (actions without a token).
#include <gtest/gtest.h>

#include "web/run_web.hpp"
#include "web/web_server.hpp"

namespace canfleet::web {
namespace {

TEST(WebListen, AddressAndPortOrPortAlone) {
  EXPECT_EQ(ParseListen("8080"), std::make_pair(std::string("127.0.0.1"), std::uint16_t{8080}));
  EXPECT_EQ(ParseListen("0.0.0.0:0"), std::make_pair(std::string("0.0.0.0"), std::uint16_t{0}));
  EXPECT_EQ(ParseListen("[::1]:9000"), std::make_pair(std::string("::1"), std::uint16_t{9000}));
  for (const char* bad : {"", "x", ":80", "127.0.0.1:", "127.0.0.1:65536", "80x", "127.0.0.1:-1"})
    EXPECT_THROW(ParseListen(bad), std::invalid_argument) << bad;
}

TEST(WebListen, LoopbackAddresses) {
  EXPECT_TRUE(IsLoopback("127.0.0.1"));
  EXPECT_TRUE(IsLoopback("127.1.2.3"));
  EXPECT_TRUE(IsLoopback("::1"));
  EXPECT_FALSE(IsLoopback("0.0.0.0"));
  EXPECT_FALSE(IsLoopback("192.168.1.5"));
  EXPECT_FALSE(IsLoopback("not an address"));
}

}  // namespace
}  // namespace canfleet::web

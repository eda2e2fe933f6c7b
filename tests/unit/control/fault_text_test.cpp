// Fault names and summaries (orchestrator/control/fault_text.hpp).
#include "orchestrator/control/fault_text.hpp"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

namespace canfleet::control {
namespace {

FaultSpec Spec(const std::string& text) {
  FaultSpec spec;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &spec)) << text;
  return spec;
}

TEST(FaultText, EveryKindHasACliNameThatParsesBack) {
  const auto& names = FaultKindNames();
  ASSERT_EQ(names.size(), 13u);
  EXPECT_EQ(names.front(), "bus-off");
  EXPECT_EQ(names.back(), "power-cycle");
  for (int k = BUS_OFF; k <= POWER_CYCLE; ++k) {
    const auto kind = static_cast<FaultKind>(k);
    const std::string name(FaultKindName(kind));
    EXPECT_EQ(name, names[static_cast<std::size_t>(k - 1)]);
    EXPECT_EQ(ParseFaultKind(name), kind) << name;
  }
}

TEST(FaultText, KindNamesAcceptTheEnumSpelling) {
  EXPECT_EQ(ParseFaultKind("HEARTBEAT_LOSS"), HEARTBEAT_LOSS);
  EXPECT_EQ(ParseFaultKind("Babbling-Idiot"), BABBLING_IDIOT);
  EXPECT_FALSE(ParseFaultKind("unspecified").has_value());
  EXPECT_FALSE(ParseFaultKind("heartbeat").has_value());
  EXPECT_EQ(FaultKindName(FAULT_KIND_UNSPECIFIED), "unspecified");
  EXPECT_EQ(FaultKindName(static_cast<FaultKind>(99)), "unspecified");
}

TEST(FaultText, Summaries) {
  const std::pair<const char*, const char*> kCases[] = {
      {"kind: HEARTBEAT_LOSS node: 'quad-5' bus: 'can0'",
       "heartbeat-loss of quad-5 on can0 (to all receivers), until cleared"},
      {"kind: HEARTBEAT_LOSS node: 'quad-5' receivers: 'quad-6' receivers: 'quad-7' duration_ms: 5000",
       "heartbeat-loss of quad-5 (to quad-6, quad-7), for 5s"},
      {"kind: DROP node: 'quad-5' bus: 'can0' cob_id: 0x185 receivers: 'quad-6' probability: 0.5 seed: 7 "
       "duration_ms: 10000",
       "drop of frames 0x185 from quad-5 on can0 (to quad-6), probability 0.5 (seed 7), for 10s"},
      {"kind: DROP bus: 'can0' cob_id: 0x180 mask: 0x780",
       "drop of frames 0x180/0x780 from any node on can0 "
       "(to all receivers), until cleared"},
      {"kind: DELAY bus: 'can1' delay_ms: 10 jitter_ms: 5 count: 100",
       "delay of all frames from any node on can1 by 10ms + 0..5ms (to all receivers), for 100 frames"},
      {"kind: CORRUPT node: 'quad-5' cob_id: 0x18FF0001 extended: true count: 1 duration_ms: 1500",
       "corrupt of frames 0x18FF0001 from quad-5, for 1.5s or 1 frame"},
      {"kind: DUPLICATE node: 'quad-5' probability: 1", "duplicate of all frames from quad-5, until cleared"},
      {"kind: PARTITION bus: 'can0' groups { nodes: 'quad-5' nodes: 'quad-6' } groups { nodes: 'quad-7' }",
       "partition of can0 into [quad-5, quad-6] and [quad-7], until cleared"},
      {"kind: RPDO_TIMEOUT node: 'quad-6' bus: 'can0' cob_id: 0x185",
       "rpdo-timeout of quad-6 on can0 (frames 0x185 no longer reach it), until cleared"},
      {"kind: BABBLING_IDIOT node: 'quad-5' bus: 'can0' duration_ms: 2000",
       "babbling-idiot quad-5 on can0 (floods 0x001 at the bus's full rate), for 2s"},
      {"kind: BUS_OFF node: 'quad-5' bus: 'can0'",
       "bus-off of quad-5 on can0, recovering after 128 x 11 recessive bits"},
      {"kind: BUS_OFF node: 'quad-5' manual_recovery: true",
       "bus-off of quad-5, manual recovery (until cleared)"},
      {"kind: ERROR_PASSIVE node: 'quad-5' bus: 'can0'", "error-passive of quad-5 on can0, until cleared"},
      {"kind: KILL node: 'quad-5'", "kill of quad-5, until cleared"},
      {"kind: RESTART node: 'quad-5'", "restart of quad-5"},
      {"kind: POWER_CYCLE node: 'quad-5'", "power-cycle of quad-5"},
      {"", "unspecified fault"},
  };
  for (const auto& [spec, summary] : kCases)
    EXPECT_EQ(SummarizeFault(Spec(spec)), summary) << spec;
}

TEST(FaultText, CanIds) {
  EXPECT_EQ(FormatCanId(0x1, false), "0x001");
  EXPECT_EQ(FormatCanId(0x7FF, false), "0x7FF");
  EXPECT_EQ(FormatCanId(0x1ABCDEF, true), "0x01ABCDEF");
}

}  // namespace
}  // namespace canfleet::control

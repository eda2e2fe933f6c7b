#pragma once
// Text of the wire protocol's control messages for test expectations, in protobuf's short text
// format ("request_id: 7 io_set { name: \"AIN1\" }", fields at their default left out). The wire
// schema is LITE_RUNTIME (bus/wire/CMakeLists.txt), whose messages have no ShortDebugString.

#include <string>

#include "bus/wire/canfleet_wire.pb.h"

namespace canfleet::test {

std::string WireText(const wire::Hello& m);
std::string WireText(const wire::HelloReply& m);
std::string WireText(const wire::NodeRequest& m);
std::string WireText(const wire::NodeReply& m);

}  // namespace canfleet::test

#pragma once
/// @file The orchestrator's SDO client on one bus. SdoClient does one transfer at a time (one
/// client channel, like a master's default client SDO); requests from the control API, the
/// configurator and scenario steps wait their turn here in arrival order.

#include <cstdint>
#include <deque>
#include <functional>
#include <string>

#include "clock/scheduler.hpp"
#include "node/canopen/sdo/sdo_client.hpp"
#include "orchestrator/fleet/master_port.hpp"

namespace canfleet::fleet {

/// "SDO abort 06020000: object does not exist in the object dictionary".
std::string DescribeAbort(canopen::SdoAbort abort);

class SdoQueue {
 public:
  using ReadDone = canopen::SdoUploadCallback;
  using WriteDone = canopen::SdoDownloadCallback;

  SdoQueue(MasterPort& port, Scheduler& scheduler);

  void Read(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, bool block, ReadDone done);
  void Write(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, canopen::Bytes data, bool block,
             WriteDone done);

  std::size_t Pending() const { return jobs_.size() + (client_.Busy() ? 1 : 0); }

 private:
  struct Job {
    std::uint8_t node_id = 0;
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    bool block = false;
    bool write = false;
    canopen::Bytes data;
    ReadDone read_done;
    WriteDone write_done;
  };
  void StartNext();

  canopen::SdoClient client_;
  std::deque<Job> jobs_;
  bool starting_ = false;  ///< StartNext is on the stack (a loopback answer completes inside it)
};

}  // namespace canfleet::fleet

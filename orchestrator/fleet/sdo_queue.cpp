#include "orchestrator/fleet/sdo_queue.hpp"

#include <cstdio>

namespace canfleet::fleet {

std::string DescribeAbort(canopen::SdoAbort abort) {
  char code[16];
  std::snprintf(code, sizeof code, "%08X", static_cast<unsigned>(abort));
  return std::string("SDO abort ") + code + ": " + canopen::Describe(abort);
}

SdoQueue::SdoQueue(MasterPort& port, Scheduler& scheduler)
    : client_(port, scheduler, canopen::SdoClientOptions{.timeout = std::chrono::seconds(2)}) {
  port.OnReceive([this](const CanFrame& frame, BusTime) { client_.OnFrame(frame); });
}

void SdoQueue::Read(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, bool block, ReadDone done) {
  Job job;
  job.node_id = node_id;
  job.index = index;
  job.sub = sub;
  job.block = block;
  job.read_done = std::move(done);
  jobs_.push_back(std::move(job));
  StartNext();
}

void SdoQueue::Write(std::uint8_t node_id, std::uint16_t index, std::uint8_t sub, canopen::Bytes data,
                     bool block, WriteDone done) {
  Job job;
  job.node_id = node_id;
  job.index = index;
  job.sub = sub;
  job.block = block;
  job.write = true;
  job.data = std::move(data);
  job.write_done = std::move(done);
  jobs_.push_back(std::move(job));
  StartNext();
}

void SdoQueue::StartNext() {
  // A completion callback may queue the next job while we are still starting one: the loop below
  // picks it up instead of recursing.
  if (starting_) return;
  starting_ = true;
  while (!client_.Busy() && !jobs_.empty()) {
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    const auto mode = job.block ? canopen::SdoMode::kBlock : canopen::SdoMode::kAuto;
    bool accepted = false;
    if (job.write) {
      auto done = std::move(job.write_done);
      accepted = client_.Download(job.node_id, job.index, job.sub, job.data, mode,
                                  [this, done](canopen::SdoAbort a) {
                                    done(a);
                                    StartNext();
                                  });
      if (!accepted) done(canopen::SdoAbort::kGeneralError);
    } else {
      auto done = std::move(job.read_done);
      accepted = client_.Upload(job.node_id, job.index, job.sub, mode,
                                [this, done](canopen::SdoAbort a, canopen::Bytes data) {
                                  done(a, std::move(data));
                                  StartNext();
                                });
      if (!accepted) done(canopen::SdoAbort::kGeneralError, {});
    }
  }
  starting_ = false;
}

}  // namespace canfleet::fleet

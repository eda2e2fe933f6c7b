#include "orchestrator/fleet/frame_feed.hpp"

#include <filesystem>

#include "bus/capture/candump_log.hpp"
#include "bus/capture/pcap_writer.hpp"

namespace canfleet::fleet {

class DumpSubscription::Sink final : public broker::PortSink {
 public:
  Sink(std::string bus, const control::DumpRequest& request, std::uint64_t request_id,
       std::shared_ptr<control::Responder> responder, capture::WallTime origin)
      : bus_(std::move(bus)), request_(request), responder_(std::move(responder)), origin_(origin) {
    response_.set_id(request_id);
  }

  void Deliver(std::span<const broker::TimedFrame> frames) override {
    if (responder_->Closed()) return;
    auto* batch = response_.mutable_frames();
    batch->clear_frames();  // the Response is reused: its repeated field keeps its capacity
    for (const auto& timed : frames) {
      const CanFrame& f = timed.frame;
      if (f.error() && !request_.error_frames()) continue;
      if (request_.has_cob_id()) {
        const std::uint32_t mask = request_.has_mask() ? request_.mask() : 0x1FFFFFFF;
        if ((f.id & mask) != (request_.cob_id() & mask)) continue;
      }
      auto* out = batch->add_frames();
      out->set_bus(bus_);
      out->set_time_ns((origin_ + timed.time).time_since_epoch().count());
      out->set_id(f.id);
      out->set_extended(f.extended());
      out->set_remote(f.remote());
      out->set_error(f.error());
      if (f.remote()) {
        // The requested DLC of a remote frame travels as that many zero bytes' length.
        out->set_data(std::string(f.dlc, '\0'));
      } else {
        out->set_data(std::string(reinterpret_cast<const char*>(f.data.data()), f.dlc));
      }
    }
    if (batch->frames_size() > 0) responder_->Send(response_);
  }
  void ControllerChanged(const ControllerEvent&) override {}

 private:
  std::string bus_;
  control::DumpRequest request_;
  std::shared_ptr<control::Responder> responder_;
  capture::WallTime origin_;
  control::Response response_;
};

DumpSubscription::DumpSubscription(broker::Broker& broker, const std::vector<std::string>& buses,
                                   const control::DumpRequest& request, std::uint64_t request_id,
                                   std::shared_ptr<control::Responder> responder, capture::WallTime origin)
    : broker_(broker) {
  for (const auto& bus : buses) {
    auto sink = std::make_unique<Sink>(bus, request, request_id, responder, origin);
    ports_.push_back(broker_.Attach(bus, "canfleet-dump", *sink, capture::CaptureTap::kAttachOptions));
    sinks_.push_back(std::move(sink));
  }
}

DumpSubscription::~DumpSubscription() {
  for (const auto port : ports_)
    broker_.Detach(port);
}

Captures::~Captures() {
  for (auto& [id, capture] : captures_)
    Close(id, capture);
}

control::CaptureStarted Captures::Start(const control::CaptureStart& request) {
  const auto buses = broker_.Buses();
  if (std::find(buses.begin(), buses.end(), request.bus()) == buses.end())
    throw std::invalid_argument("no bus called '" + request.bus() + "'");
  const std::string format = request.format().empty() ? "pcap" : request.format();
  if (format != "pcap" && format != "candump")
    throw std::invalid_argument("capture format '" + format + "': pcap or candump");
  Capture capture;
  capture.bus = request.bus();
  capture.path = ResolveCapturePath(request.path(), folders_).string();
  if (format == "pcap") {
    capture.writer = std::make_unique<capture::PcapWriter>(capture.path);
  } else if (format == "candump") {
    capture.writer = std::make_unique<capture::CandumpLogWriter>(capture.path, capture.bus);
  } else {
    throw std::invalid_argument("capture format '" + format + "': pcap or candump");
  }
  capture.tap = std::make_unique<capture::CaptureTap>(*capture.writer, origin_);
  capture.port =
      broker_.Attach(capture.bus, "canfleet-capture", *capture.tap, capture::CaptureTap::kAttachOptions);
  const std::uint32_t id = next_id_++;
  control::CaptureStarted started;
  started.set_capture_id(id);
  started.set_path(capture.path);
  captures_.emplace(id, std::move(capture));
  return started;
}

std::string Captures::Close(std::uint32_t id, Capture& capture) {
  broker_.Detach(capture.port);
  capture.writer->Close();
  std::string line = "capture " + std::to_string(id) + ": " + std::to_string(capture.tap->frames()) +
                     " frames of " + capture.bus + " in " + capture.path;
  if (!capture.writer->ok()) line += " (write error: " + capture.writer->error() + ")";
  return line;
}

std::string Captures::Stop(std::uint32_t id) {
  if (id == 0) {
    std::string lines;
    for (auto& [cid, capture] : captures_)
      lines += (lines.empty() ? "" : "\n") + Close(cid, capture);
    captures_.clear();
    return lines.empty() ? "no capture running" : lines;
  }
  auto it = captures_.find(id);
  if (it == captures_.end()) throw std::invalid_argument("no capture " + std::to_string(id));
  std::string line = Close(id, it->second);
  captures_.erase(it);
  return line;
}

}  // namespace canfleet::fleet

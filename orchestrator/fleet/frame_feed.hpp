#pragma once
/// @file Frames leaving the broker for people and files: live dumps streamed to control clients
/// (`canfleet dump`) and capture files (`canfleet capture start|stop`). Each is a listen-only
/// port, so watching a bus never changes it (a lone node still sees its ACK errors).

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bus/capture/capture_writer.hpp"
#include "orchestrator/broker/broker.hpp"
#include "orchestrator/capture/capture_tap.hpp"
#include "orchestrator/control/control_handler.hpp"
#include "orchestrator/fleet/capture_path.hpp"

namespace canfleet::fleet {

/// One `canfleet dump`: frames of the asked buses, filtered, one Response per broker round.
class DumpSubscription {
 public:
  /// @throws std::invalid_argument for an unknown bus.
  DumpSubscription(broker::Broker& broker, const std::vector<std::string>& buses,
                   const control::DumpRequest& request, std::uint64_t request_id,
                   std::shared_ptr<control::Responder> responder, capture::WallTime origin);
  ~DumpSubscription();
  DumpSubscription(const DumpSubscription&) = delete;
  DumpSubscription& operator=(const DumpSubscription&) = delete;

 private:
  class Sink;
  broker::Broker& broker_;
  std::vector<std::unique_ptr<Sink>> sinks_;
  std::vector<broker::PortId> ports_;
};

/// Capture files, by id.
class Captures {
 public:
  Captures(broker::Broker& broker, capture::WallTime origin, CaptureFolders folders)
      : broker_(broker), origin_(origin), folders_(std::move(folders)) {}
  ~Captures();

  /// Starts writing `bus` to `path` ("pcap" or "candump"), a file that must not exist yet inside
  /// the fleet's folders (capture_path.hpp; relative: in the capture folder). Returns the id and
  /// the absolute path. @throws std::invalid_argument (unknown bus or format, a path refused) or
  /// std::system_error (file).
  control::CaptureStarted Start(const control::CaptureStart& request);
  /// Stops one capture (0: every one). Returns a line for the CLI. @throws std::invalid_argument.
  std::string Stop(std::uint32_t id);

 private:
  struct Capture {
    std::string bus;
    std::string path;
    std::unique_ptr<capture::CaptureWriter> writer;
    std::unique_ptr<capture::CaptureTap> tap;
    broker::PortId port = 0;
  };
  std::string Close(std::uint32_t id, Capture& capture);

  broker::Broker& broker_;
  capture::WallTime origin_;
  CaptureFolders folders_;
  std::map<std::uint32_t, Capture> captures_;
  std::uint32_t next_id_ = 1;
};

}  // namespace canfleet::fleet

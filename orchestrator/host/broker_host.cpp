#include "orchestrator/host/broker_host.hpp"

#include <malloc.h>

#include <spdlog/spdlog.h>

#include <cmath>
#include <csignal>
#include <stdexcept>

namespace canfleet::host {

namespace {

socketcand::ServerOptions WithOrigin(socketcand::ServerOptions options, WallTime origin) {
  if (!options.wall_origin) options.wall_origin = origin;
  return options;
}

std::unique_ptr<Scheduler> MakeScheduler(asio::io_context& io, const HostTime& time) {
  if (time.virtual_time) return std::make_unique<GrantedScheduler>();
  return std::make_unique<AsioScheduler>(io);
}

std::unique_ptr<transport::TimeConductor> MakeConductor(asio::io_context& io, Scheduler& scheduler,
                                                        broker::Broker& broker, const HostTime& time) {
  if (!time.virtual_time) return nullptr;
  return std::make_unique<transport::TimeConductor>(io, static_cast<GrantedScheduler&>(scheduler), broker,
                                                    time.conductor);
}

/// Large buffers straight from and back to the kernel. glibc raises its mmap threshold (up to
/// 32 MiB) after the first large block is freed, after which what a flood of clients made the
/// orchestrator buffer (session queues, half-sent messages) stays in the heap once they are gone:
/// 16 MiB before such a flood, 108 MiB after it. A fixed threshold keeps every block above it an
/// mmap of its own, returned when freed; the hot paths reuse their buffers, so this costs no
/// syscalls per frame.
void ReturnLargeBlocksWhenFreed() {
  mallopt(M_MMAP_THRESHOLD, 256 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024);
}

transport::BrokerServerOptions ServerOptions(transport::TimeConductor* conductor, WallTime wall_origin) {
  transport::BrokerServerOptions options;
  options.time_conductor = conductor;
  options.wall_origin = wall_origin;
  return options;
}

}  // namespace

double ParseSpeed(const std::string& text) {
  if (text == "max") return 0;
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(value) || value <= 0)
    throw std::invalid_argument("--speed " + text + ": give max or a positive factor of real time (10, 0.5)");
  return value;
}

BrokerHost::BrokerHost(asio::io_context& io, socketcand::ServerOptions socketcand_options, HostTime time)
    : io_(io),
      scheduler_(MakeScheduler(io, time)),
      wall_origin_(time.virtual_time ? WallTime{} : WallClockOrigin(*scheduler_)),
      broker_(*scheduler_),
      conductor_(MakeConductor(io, *scheduler_, broker_, time)),
      server_(io, broker_, ServerOptions(conductor_.get(), wall_origin_)),
      socketcand_(io, broker_, *scheduler_, WithOrigin(std::move(socketcand_options), wall_origin_)),
      signals_(io, SIGINT, SIGTERM),
      drain_(io) {
  ReturnLargeBlocksWhenFreed();
}

BrokerHost::~BrokerHost() {
  // Dispose the buses' BusStats (monitors drop them) before the broker goes.
  bus_telemetry_.reset();
  publisher_.reset();
  participant_.reset();
}

void BrokerHost::AddBus(const broker::BusConfig& config) {
  if (conductor_ && !config.paced)
    throw std::invalid_argument("bus " + config.name +
                                ": an unpaced bus has no time line, so it cannot run in virtual time");
  broker_.AddBus(config);
  spdlog::info("bus {}: {} bit/s, {}", config.name, config.bitrate, config.paced ? "paced" : "unpaced");
}

std::uint16_t BrokerHost::ServeSocketcand(const std::string& bus, std::uint16_t port) {
  if (conductor_)
    throw std::invalid_argument("bus " + bus +
                                ": socketcand is not served in virtual time (its clients live in real time; "
                                "watch the bus with canfleet dump or a monitor instead)");
  const std::uint16_t bound = socketcand_.Serve(bus, port);
  spdlog::info("bus {}: socketcand on port {}", bus, bound);
  return bound;
}

wire::Endpoint BrokerHost::Listen(const wire::Endpoint& endpoint) {
  return server_.Listen(endpoint);
}

bool BrokerHost::StartTelemetry(const telemetry::DdsOptions& dds, std::chrono::milliseconds period) {
  try {
    participant_.emplace(dds);
    publisher_.emplace(*participant_, telemetry::OrchestratorTelemetryOptions{.period = period});
    broker::BrokerTelemetryOptions options;
    options.period = period;
    if (conductor_) options.virtual_time_factor = [c = conductor_.get()] { return c->Factor(); };
    bus_telemetry_.emplace(broker_, *scheduler_, *publisher_, options);
    spdlog::info("telemetry on DDS domain {}", dds.domain_id);
    return true;
  } catch (const std::exception& e) {
    spdlog::error("telemetry: {}; running without telemetry", e.what());
    bus_telemetry_.reset();
    publisher_.reset();
    participant_.reset();
    return false;
  }
}

void BrokerHost::OnSignal(std::function<void(const char* name)> handler) {
  signals_.async_wait([handler = std::move(handler)](const asio::error_code& ec, int signal) {
    if (!ec) handler(signal == SIGINT ? "SIGINT" : "SIGTERM");
  });
}

void BrokerHost::Stop() {
  if (stopping_) return;
  stopping_ = true;
  socketcand_.Stop();
  server_.Close();  // sessions say "broker shutting down" and detach
  // Let the farewells leave, then stop whatever the broker still has armed.
  drain_.expires_after(std::chrono::milliseconds(200));
  drain_.async_wait([this](const asio::error_code&) { io_.stop(); });
}

}  // namespace canfleet::host

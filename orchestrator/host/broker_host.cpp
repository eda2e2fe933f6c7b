#include "orchestrator/host/broker_host.hpp"

#include <spdlog/spdlog.h>

#include <csignal>

namespace canfleet::host {

namespace {

socketcand::ServerOptions WithOrigin(socketcand::ServerOptions options, WallTime origin) {
  if (!options.wall_origin) options.wall_origin = origin;
  return options;
}

}  // namespace

BrokerHost::BrokerHost(asio::io_context& io, socketcand::ServerOptions socketcand_options)
    : io_(io),
      scheduler_(io),
      wall_origin_(WallClockOrigin(scheduler_)),
      broker_(scheduler_),
      server_(io, broker_),
      socketcand_(io, broker_, scheduler_, WithOrigin(std::move(socketcand_options), wall_origin_)),
      signals_(io, SIGINT, SIGTERM),
      drain_(io) {}

BrokerHost::~BrokerHost() {
  // Dispose the buses' BusStats (monitors drop them) before the broker goes.
  bus_telemetry_.reset();
  publisher_.reset();
  participant_.reset();
}

void BrokerHost::AddBus(const broker::BusConfig& config) {
  broker_.AddBus(config);
  spdlog::info("bus {}: {} bit/s, {}", config.name, config.bitrate, config.paced ? "paced" : "unpaced");
}

std::uint16_t BrokerHost::ServeSocketcand(const std::string& bus, std::uint16_t port) {
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
    bus_telemetry_.emplace(broker_, scheduler_, *publisher_,
                           broker::BrokerTelemetryOptions{.period = period});
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

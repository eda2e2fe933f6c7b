// A broker with one bus served over socketcand, for python_can_bench.py (python-can's socketcand
// interface against canfleet). Not a test.
//
//   canfleet_socketcand_bench_server [paced|unpaced, default unpaced] [port, default 0 = any]
//
// Prints "ready PORT" once listening; runs until SIGINT/SIGTERM.

// First, before any standard header (see bench/broker/broker_bench.cpp).
#include "clock/asio_scheduler.hpp"

#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <csignal>
#include <cstdio>
#include <string>

#include "orchestrator/broker/broker.hpp"
#include "orchestrator/socketcand/server.hpp"

int main(int argc, char** argv) {
  using namespace canfleet;
  const bool paced = argc > 1 && std::string(argv[1]) == "paced";
  const auto port = static_cast<std::uint16_t>(argc > 2 ? std::stoi(argv[2]) : 0);
  asio::io_context io;
  AsioScheduler scheduler(io);
  broker::Broker broker(scheduler);
  broker.AddBus({.name = "can0", .bitrate = 1'000'000, .paced = paced});
  socketcand::Server server(io, broker, scheduler);
  std::printf("ready %u\n", static_cast<unsigned>(server.Serve("can0", port)));
  std::fflush(stdout);
  asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const asio::error_code&, int) {
    server.Stop();
    io.stop();
  });
  io.run();
  return 0;
}

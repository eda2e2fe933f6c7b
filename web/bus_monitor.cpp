#include "web/bus_monitor.hpp"

#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <asio/post.hpp>
#include <map>
#include <thread>

#include "bus/broker_client/broker_client_port.hpp"

namespace canfleet::web {

struct BusMonitor::Impl {
  std::string endpoint;
  std::string token;
  FrameHandler on_frame;
  asio::io_context io;
  asio::executor_work_guard<asio::io_context::executor_type> work{io.get_executor()};
  std::map<std::string, std::unique_ptr<BrokerClientPort>> ports;  ///< io thread only
  std::thread thread;
};

BusMonitor::BusMonitor(std::string endpoint, std::string token, FrameHandler on_frame)
    : impl_(std::make_unique<Impl>()) {
  impl_->token = std::move(token);
  impl_->endpoint = std::move(endpoint);
  impl_->on_frame = std::move(on_frame);
  impl_->thread = std::thread([impl = impl_.get()] { impl->io.run(); });
}

BusMonitor::~BusMonitor() {
  asio::post(impl_->io, [impl = impl_.get()] {
    impl->ports.clear();
    impl->work.reset();
  });
  impl_->thread.join();
}

void BusMonitor::Watch(const std::string& bus) {
  asio::post(impl_->io, [impl = impl_.get(), bus] {
    if (impl->ports.contains(bus)) return;
    BrokerClientOptions options;
    options.endpoint = impl->endpoint;
    options.bus = bus;
    options.node_name = "canfleet-web";
    options.monitor = true;
    options.token = impl->token;
    auto port = std::make_unique<BrokerClientPort>(impl->io, options);
    port->OnReceive(
        [impl, bus](const CanFrame& frame, BusTime time) { impl->on_frame(bus, frame, time.count()); });
    impl->ports.emplace(bus, std::move(port));
  });
}

}  // namespace canfleet::web

// canfleet-bus-client: joins a broker's virtual bus as a node (or a monitor), prints what it
// receives and sends what it is told. A cansend/candump for canfleet buses, and the node-side
// test client of the system tests.
//
// Output on stdout, one line per event, flushed at once:
//   connected port=3 bitrate=500000 paced
//   rx 1234567 123#00000001          (bus time in ns, candump frame)
//   state error-passive tec=128 rec=0
//   sent 100                          (a send command is done: every frame confirmed by the bus)
//   disconnected <reason>
//   summary rx=100 tx=100
// Commands on stdin (and --send at the first connection):
//   send ID COUNT    COUNT data frames with identifier ID (hex); data = 4-byte big-endian sequence
//   frame 123#DEAD   one frame in candump syntax
//   quit
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/post.hpp>
#include <asio/read_until.hpp>
#include <asio/signal_set.hpp>
#include <asio/steady_timer.hpp>
#include <asio/streambuf.hpp>
#include <cstdio>
#include <deque>
#include <istream>
#include <sstream>
#include <string>

#include "bus/broker_client/broker_client_port.hpp"

namespace {

using canfleet::BrokerClientPort;
using canfleet::CanFrame;

/// Frames the bus has not confirmed yet, at most: keeps the broker's TX queue from overflowing.
constexpr std::size_t kWindow = 256;

bool ParseCandump(const std::string& text, CanFrame& frame) {
  const auto hash = text.find('#');
  if (hash == std::string::npos || hash == 0 || hash > 8) return false;
  frame = CanFrame{};
  try {
    frame.id = static_cast<std::uint32_t>(std::stoul(text.substr(0, hash), nullptr, 16));
  } catch (const std::exception&) {
    return false;
  }
  if (hash > 3) frame.flags |= CanFrame::kExtended;
  const std::string rest = text.substr(hash + 1);
  if (!rest.empty() && rest[0] == 'R') {
    frame.flags |= CanFrame::kRemote;
    frame.dlc = rest.size() > 1 ? static_cast<std::uint8_t>(rest[1] - '0') : 0;
    return frame.valid();
  }
  if (rest.size() % 2 != 0 || rest.size() > 16) return false;
  for (std::size_t i = 0; i < rest.size(); i += 2) {
    try {
      frame.data[frame.dlc++] = static_cast<std::uint8_t>(std::stoul(rest.substr(i, 2), nullptr, 16));
    } catch (const std::exception&) {
      return false;
    }
  }
  return frame.valid();
}

class Client {
 public:
  Client(asio::io_context& io, canfleet::BrokerClientOptions options, std::size_t exit_after)
      : io_(io), port_(io, std::move(options)), input_(io), exit_after_(exit_after) {
    port_.OnReceive([this](const CanFrame& frame, canfleet::BusTime time) {
      ++received_;
      if (print_) {
        std::printf("rx %lld %s\n", static_cast<long long>(time.count()), canfleet::ToCandump(frame).c_str());
        ScheduleStdoutFlush();
      }
      if (exit_after_ != 0 && received_ >= exit_after_) Quit();
    });
    port_.OnStateChange([this](const canfleet::ControllerEvent& e) {
      std::printf("state %s tec=%u rec=%u\n", canfleet::ToString(e.state), e.tec, e.rec);
      ScheduleStdoutFlush();
    });
    port_.OnTxConfirmed([this](const CanFrame&, canfleet::BusTime) {
      ++confirmed_;
      Pump();
    });
    port_.OnConnection([this](bool connected, const std::string& detail) {
      if (connected) {
        const auto s = port_.Session();
        std::printf("connected port=%u bitrate=%u %s\n", s->port_id, s->bitrate,
                    s->paced ? "paced" : "unpaced");
        if (!initial_.empty()) {
          for (const auto& c : initial_)
            Command(c);
          initial_.clear();
        }
      } else {
        std::printf("disconnected %s\n", detail.c_str());
        // Frames not yet confirmed are lost with the connection.
        pending_.clear();
        outstanding_ = 0;
        confirmed_ = 0;
        sent_ = 0;
      }
      std::fflush(stdout);
    });
  }

  void SetPrint(bool print) { print_ = print; }
  void AddInitialCommand(std::string command) { initial_.push_back(std::move(command)); }

  void ReadStdin() {
    input_.assign(::dup(STDIN_FILENO));
    ReadLine();
  }

  void Command(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    in >> verb;
    if (verb == "send") {
      std::string id_text;
      std::size_t count = 0;
      in >> id_text >> count;
      const auto id = static_cast<std::uint32_t>(std::stoul(id_text, nullptr, 16));
      for (std::size_t i = 0; i < count; ++i) {
        const auto seq = static_cast<std::uint32_t>(next_seq_++);
        pending_.push_back(CanFrame::Data(id, {std::uint8_t(seq >> 24), std::uint8_t(seq >> 16),
                                               std::uint8_t(seq >> 8), std::uint8_t(seq)}));
      }
      requested_ += count;
      Pump();
    } else if (verb == "frame") {
      std::string text;
      in >> text;
      CanFrame frame;
      if (!ParseCandump(text, frame)) {
        std::printf("error bad frame %s\n", text.c_str());
        std::fflush(stdout);
        return;
      }
      pending_.push_back(frame);
      requested_ += 1;
      Pump();
    } else if (verb == "quit") {
      Quit();
    } else if (!verb.empty()) {
      std::printf("error unknown command %s\n", verb.c_str());
      std::fflush(stdout);
    }
  }

  void Quit() {
    std::printf("summary rx=%zu tx=%zu\n", received_, confirmed_total_ + confirmed_);
    std::fflush(stdout);
    io_.stop();
  }

 private:
  /// stdout is a pipe in tests: flush once per io_context turn, not once per line.
  void ScheduleStdoutFlush() {
    if (flush_posted_) return;
    flush_posted_ = true;
    asio::post(io_, [this] {
      flush_posted_ = false;
      std::fflush(stdout);
    });
  }

  void ReadLine() {
    asio::async_read_until(input_, line_buffer_, '\n', [this](const asio::error_code& ec, std::size_t) {
      if (ec) return;  // stdin closed: keep running until quit, a signal or --exit-after
      std::istream in(&line_buffer_);
      std::string line;
      std::getline(in, line);
      Command(line);
      ReadLine();
    });
  }

  /// Sends queued frames while fewer than kWindow are unconfirmed; says "sent N" when every
  /// requested frame has been confirmed.
  void Pump() {
    while (!pending_.empty() && sent_ - confirmed_ < kWindow) {
      if (!port_.Send(pending_.front())) break;
      pending_.pop_front();
      ++sent_;
    }
    if (requested_ != 0 && pending_.empty() && confirmed_ == sent_) {
      confirmed_total_ += confirmed_;
      std::printf("sent %zu\n", requested_);
      std::fflush(stdout);
      requested_ = 0;
      sent_ = confirmed_ = 0;
    }
  }

  asio::io_context& io_;
  BrokerClientPort port_;
  asio::posix::stream_descriptor input_;
  asio::streambuf line_buffer_;
  std::vector<std::string> initial_;
  std::deque<CanFrame> pending_;
  std::size_t requested_ = 0, sent_ = 0, confirmed_ = 0, confirmed_total_ = 0, outstanding_ = 0;
  std::size_t next_seq_ = 0;
  std::size_t received_ = 0;
  std::size_t exit_after_;
  bool print_ = true;
  bool flush_posted_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"canfleet-bus-client: join a canfleet broker's virtual bus, print and send frames"};
  canfleet::BrokerClientOptions options;
  options.tx_confirmations = true;
  std::vector<std::string> sends;
  std::size_t exit_after = 0;
  double timeout_s = 0;
  bool quiet = false;
  bool commands = false;
  std::string log_level = "info";
  app.add_option("--connect", options.endpoint, "tcp://HOST:PORT or unix:///PATH")->required();
  app.add_option("--bus", options.bus, "Bus name")->capture_default_str();
  app.add_option("--name", options.node_name, "Name shown in the broker's logs");
  app.add_option("--node-id", options.node_id, "CANopen node-ID (0 = none)");
  app.add_flag("--monitor", options.monitor, "Listen only, with error frames");
  app.add_option("--send", sends, "ID:COUNT: send COUNT frames with identifier ID (hex) once connected");
  app.add_flag("--stdin", commands, "Read commands from stdin: send ID COUNT | frame 123#DEAD | quit");
  app.add_option("--exit-after", exit_after, "Exit after receiving this many frames");
  app.add_option("--timeout", timeout_s, "Exit with status 1 after this many seconds");
  app.add_flag("--quiet", quiet, "Do not print received frames (counts only)");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical or off");
  CLI11_PARSE(app, argc, argv);

  spdlog::set_default_logger(spdlog::stderr_color_mt("canfleet-bus-client"));
  spdlog::set_level(spdlog::level::from_str(log_level));

  asio::io_context io(1);
  std::unique_ptr<Client> client;
  try {
    client = std::make_unique<Client>(io, options, exit_after);
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 2;
  }
  client->SetPrint(!quiet);
  for (auto s : sends) {
    const auto colon = s.find(':');
    if (colon == std::string::npos) {
      spdlog::critical("--send {}: expected ID:COUNT", s);
      return 2;
    }
    client->AddInitialCommand("send " + s.substr(0, colon) + " " + s.substr(colon + 1));
  }
  if (commands) client->ReadStdin();

  int status = 0;
  asio::steady_timer deadline(io);
  if (timeout_s > 0) {
    deadline.expires_after(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(timeout_s)));
    deadline.async_wait([&](const asio::error_code& ec) {
      if (ec) return;
      spdlog::error("timeout after {} s", timeout_s);
      status = 1;
      client->Quit();
    });
  }
  asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const asio::error_code& ec, int) {
    if (!ec) client->Quit();
  });
  io.run();
  client.reset();
  return status;
}

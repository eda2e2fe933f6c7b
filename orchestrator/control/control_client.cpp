#include "orchestrator/control/control_client.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <asio/connect.hpp>
#include <asio/write.hpp>
#include <cerrno>
#include <cstring>

#include "bus/wire/auth_token.hpp"
#include "orchestrator/control/duration_text.hpp"

namespace canfleet::control {

namespace {

using Clock = std::chrono::steady_clock;

constexpr std::string_view kIsItRunning = " (is `canfleet up` running?)";

std::chrono::milliseconds Remaining(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return left.count() < 0 ? std::chrono::milliseconds(0) : left;
}

}  // namespace

ControlClient::ControlClient(const std::string& endpoint, std::chrono::milliseconds connect_timeout)
    : endpoint_(endpoint), socket_(io_) {
  const wire::Endpoint ep = ParseControlEndpoint(endpoint);
  asio::ip::tcp::resolver resolver(io_);
  asio::error_code ec;
  const auto results = resolver.resolve(ep.host, std::to_string(ep.port), ec);
  if (ec) throw ControlError("cannot resolve \"" + ep.host + "\" of " + endpoint_ + ": " + ec.message());

  bool done = false;
  asio::async_connect(socket_, results, [&](const asio::error_code& connect_ec, const auto&) {
    ec = connect_ec;
    done = true;
  });
  io_.run_for(connect_timeout);
  if (!done) {
    asio::error_code ignored;
    socket_.close(ignored);
    io_.restart();
    io_.run();  // lets the cancelled connect finish
    throw ControlError("no orchestrator answered at " + endpoint_ + " within " +
                       FormatDuration(connect_timeout) + std::string(kIsItRunning));
  }
  if (ec == asio::error::connection_refused)
    throw ControlError("no orchestrator at " + endpoint_ + std::string(kIsItRunning));
  if (ec)
    throw ControlError("cannot connect to " + endpoint_ + ": " + ec.message() + std::string(kIsItRunning));
  asio::error_code ignored;
  socket_.set_option(asio::ip::tcp::no_delay(true), ignored);
  SendToken();
}

void ControlClient::SendToken() {
  std::optional<std::string> token;
  try {
    token = wire::ResolveToken();
  } catch (const std::runtime_error& e) {
    Close();
    throw ControlError(e.what());
  }
  if (!token) return;  // a loopback orchestrator needs none; one beyond it says so
  const std::string preamble = wire::EncodeAuthPreamble(*token);
  asio::error_code ec;
  asio::write(socket_, asio::buffer(preamble), ec);
  if (ec) {
    Close();
    throw ControlError("lost the connection to the orchestrator at " + endpoint_ + ": " + ec.message());
  }
}

ControlClient::~ControlClient() {
  Close();
}

void ControlClient::Close() {
  asio::error_code ignored;
  if (!socket_.is_open()) return;
  socket_.shutdown(asio::socket_base::shutdown_both, ignored);
  socket_.close(ignored);
}

std::uint64_t ControlClient::Send(Request request) {
  if (!socket_.is_open()) throw ControlError("not connected to " + endpoint_);
  if (request.id() == 0) request.set_id(next_id_++);
  std::string bytes;
  if (!AppendDelimited(request, bytes))
    throw ControlError("request of " + std::to_string(request.ByteSizeLong()) +
                       " bytes exceeds the limit of " + std::to_string(kMaxControlMessage));
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(socket_.native_handle(), bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = std::strerror(errno);
      ThrowRefusalIfAny();
      Close();
      throw ControlError("lost the connection to the orchestrator at " + endpoint_ + ": " + why);
    }
    sent += static_cast<std::size_t>(n);
  }
  return request.id();
}

Response ControlClient::Call(Request request, std::chrono::milliseconds timeout) {
  const std::uint64_t id = Send(std::move(request));
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    std::optional<Response> r = NextBuffered();
    if (!r && ReadSome(Remaining(deadline))) r = NextBuffered();
    if (r) {
      if (r->id() == id) return std::move(*r);
      if (r->id() == 0 && !r->error().empty())
        throw ControlError("the orchestrator at " + endpoint_ + " refused the request: " + r->error());
      pending_.push_back(std::move(*r));
      continue;
    }
    if (Clock::now() >= deadline)
      throw ControlError("no response from the orchestrator at " + endpoint_ + " within " +
                         FormatDuration(timeout));
  }
}

std::optional<Response> ControlClient::Receive(std::chrono::milliseconds timeout) {
  if (!pending_.empty()) {
    Response r = std::move(pending_.front());
    pending_.pop_front();
    return r;
  }
  if (auto r = NextBuffered()) return r;
  if (!ReadSome(timeout)) return std::nullopt;
  return NextBuffered();
}

void ControlClient::ThrowRefusalIfAny() {
  // A refused connection (no or wrong token, too many clients) carries its reason as an error
  // Response with id 0, which may be waiting unread when a send fails.
  std::array<char, 4096> buffer;
  const ssize_t n = ::recv(socket_.native_handle(), buffer.data(), buffer.size(), MSG_DONTWAIT);
  if (n <= 0) return;
  reader_.Append(buffer.data(), static_cast<std::size_t>(n));
  Response r;
  if (reader_.Next(r) == DelimitedReader::Result::kMessage && r.id() == 0 && !r.error().empty()) {
    Close();
    throw ControlError("the orchestrator at " + endpoint_ + " refused the connection: " + r.error());
  }
}

std::optional<Response> ControlClient::NextBuffered() {
  Response r;
  switch (reader_.Next(r)) {
    case DelimitedReader::Result::kMessage:
      return r;
    case DelimitedReader::Result::kNeedMore:
      return std::nullopt;
    case DelimitedReader::Result::kError:
      break;
  }
  Close();
  throw ControlError("malformed data from " + endpoint_ + ": " + reader_.Error());
}

bool ControlClient::ReadSome(std::chrono::milliseconds timeout) {
  if (!socket_.is_open())
    throw ControlError("the connection to the orchestrator at " + endpoint_ + " is closed");
  pollfd p{socket_.native_handle(), POLLIN, 0};
  const int ready =
      ::poll(&p, 1, static_cast<int>(std::min<std::chrono::milliseconds::rep>(timeout.count(), 1 << 30)));
  if (ready <= 0) return false;  // timeout, or EINTR: let the caller look at its flags
  std::array<char, 64 * 1024> buffer;
  const ssize_t n = ::recv(socket_.native_handle(), buffer.data(), buffer.size(), 0);
  if (n == 0) {
    Close();
    throw ControlError("the orchestrator at " + endpoint_ + " closed the connection");
  }
  if (n < 0 && errno == ECONNRESET) {
    Close();
    throw ControlError("the orchestrator at " + endpoint_ + " reset the connection");
  }
  if (n < 0) {
    if (errno == EINTR || errno == EAGAIN) return false;
    const std::string why = std::strerror(errno);
    Close();
    throw ControlError("lost the connection to the orchestrator at " + endpoint_ + ": " + why);
  }
  reader_.Append(buffer.data(), static_cast<std::size_t>(n));
  return true;
}

}  // namespace canfleet::control

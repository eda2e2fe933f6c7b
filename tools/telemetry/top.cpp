#include "tools/telemetry/top.hpp"

#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <iostream>
#include <thread>

#include "telemetry/cli_options.hpp"
#include "telemetry/fleet_reader.hpp"
#include "tools/telemetry/nothing_seen.hpp"

namespace canfleet::tools {

namespace {

std::atomic<bool> g_stop{false};

extern "C" void OnTopStopSignal(int) {
  g_stop = true;
}

/// Puts the terminal in non-canonical, no-echo mode and an alternate screen; restores on destruction.
class RawTerminal {
 public:
  RawTerminal() {
    if (tcgetattr(STDIN_FILENO, &saved_) != 0) return;
    termios raw = saved_;
    raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO));
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
    std::cout << "\x1b[?1049h\x1b[?25l" << std::flush;  // alternate screen, hide cursor
  }
  ~RawTerminal() {
    std::cout << "\x1b[?25h\x1b[?1049l" << std::flush;
    if (active_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;

 private:
  termios saved_{};
  bool active_ = false;
};

void TerminalSize(int& width, int& height) {
  winsize size{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0 && size.ws_row > 0) {
    width = size.ws_col;
    height = size.ws_row;
  }
}

/// Keyboard state of the interactive mode.
struct Keys {
  bool quit = false;
  bool editing = false;
  std::string escape;  // pending escape sequence
};

/// Moves the selection by `delta` rows and turns to its page.
void Select(int delta, RenderSettings& settings, const FleetView& view) {
  const auto rows = SelectRows(view, settings.filter, settings.sort, settings.reverse, settings.now);
  settings.selected = MoveSelection(rows, settings.selected, delta);
  if (!settings.selected) return;
  const auto page =
      PageOf(rows, *settings.selected, RowsPerPage(settings, StatusLines(view, settings.filter)));
  if (page) settings.page = *page;
}

/// A complete escape sequence (arrows "\x1b[A".."\x1b[D", PgUp "\x1b[5~", PgDn "\x1b[6~"; a lone
/// Esc is decided by the caller when a read ends on it).
void HandleEscape(const std::string& sequence, RenderSettings& settings, const FleetView& view) {
  if (sequence == "\x1b") {
    settings.detail = false;
  } else if (sequence == "\x1b[A") {
    Select(-1, settings, view);
  } else if (sequence == "\x1b[B") {
    Select(+1, settings, view);
  } else if (sequence == "\x1b[C") {
    if (settings.selected) settings.detail = true;
  } else if (sequence == "\x1b[D") {
    settings.detail = false;
  } else if (sequence == "\x1b[5~") {
    --settings.page;
  } else if (sequence == "\x1b[6~") {
    ++settings.page;
  }
}

/// True once `sequence` (starting with Esc) is complete: CSI sequences end in a byte 40h..7Eh.
bool EscapeComplete(const std::string& sequence) {
  if (sequence.size() < 2) return false;
  if (sequence.size() < 3) return false;
  const char last = sequence.back();
  return (last >= 0x40 && last <= 0x7e) || sequence.size() >= 8;
}

void HandleKey(char c, Keys& keys, RenderSettings& settings, const FleetView& view) {
  if (keys.editing) {
    if (c == '\n' || c == '\r') {
      keys.editing = false;
      settings.filter.text = settings.filter_prompt;
      settings.filter_prompt.clear();
    } else if (c == 0x1b) {
      keys.editing = false;
      settings.filter_prompt.clear();
    } else if (c == 0x7f || c == 0x08) {
      if (!settings.filter_prompt.empty()) settings.filter_prompt.pop_back();
    } else if (c >= 0x20 && c < 0x7f) {
      settings.filter_prompt += c;
    }
    return;
  }
  if (keys.escape == "\x1b" && c != '[' && c != 'O') {  // Esc, then another key
    HandleEscape(keys.escape, settings, view);
    keys.escape.clear();
  }
  if (!keys.escape.empty() || c == 0x1b) {
    keys.escape += c;
    if (EscapeComplete(keys.escape)) {
      HandleEscape(keys.escape, settings, view);
      keys.escape.clear();
    }
    return;
  }
  if (settings.detail) {  // the node detail screen: back, other nodes, quit
    if (c == 'q') keys.quit = true;
    if (c == 0x7f || c == 0x08) settings.detail = false;
    return;
  }
  switch (c) {
    case 'q':
      keys.quit = true;
      break;
    case '\n':
    case '\r':
      if (!settings.selected) Select(0, settings, view);
      settings.detail = settings.selected.has_value();
      break;
    case 'n':
    case ' ':
      ++settings.page;
      break;
    case 'p':
      --settings.page;
      break;
    case 's':
      settings.sort = NextSortKey(settings.sort);
      break;
    case 'r':
      settings.reverse = !settings.reverse;
      break;
    case 'f':
      settings.filter.state = settings.filter.state == "fault" ? "" : "fault";
      break;
    case 'a':
      settings.filter.state.clear();
      break;
    case 'c':
      settings.filter = {};
      break;
    case 'b': {  // cycle through the buses, then all
      const auto& buses = view.buses();
      std::vector<std::string> names;
      for (const auto& [key, row] : view.nodes()) {
        if (names.empty() || names.back() != key.bus) names.push_back(key.bus);
      }
      for (const auto& [name, bus] : buses) {
        if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
      }
      auto it = std::find(names.begin(), names.end(), settings.filter.bus);
      settings.filter.bus = (settings.filter.bus.empty() || it == names.end() || it + 1 == names.end())
                                ? (settings.filter.bus.empty() && !names.empty() ? names.front() : "")
                                : *(it + 1);
      settings.page = 0;
      break;
    }
    case '/':
      keys.editing = true;
      settings.filter_prompt.clear();
      break;
    default:
      break;
  }
}

}  // namespace

void AddTopOptions(CLI::App& app, TopOptions& options) {
  telemetry::AddDdsOptions(app, options.dds);
  app.add_option("--bus", options.filter.bus, "only this bus");
  app.add_option("--state", options.filter.state,
                 "only nodes in this state: operational pre-operational stopped initialising, error-active "
                 "error-passive bus-off, fault, ok")
      ->check(
          [](const std::string& s) { return IsValidStateFilter(s) ? std::string() : "unknown state " + s; });
  app.add_option("--filter", options.filter.text,
                 "only nodes whose 'bus #id name device' contains this text");
  app.add_option_function<std::string>(
         "--sort",
         [&options](const std::string& s) {
           const auto key = ParseSortKey(s);
           if (!key) throw CLI::ValidationError("--sort", "unknown sort key " + s);
           options.sort = *key;
         },
         "node (bus, id), name, state, errors, change (latest first), device")
      ->default_str("node");
  app.add_flag("--reverse", options.reverse, "reverse the order");
  app.add_option_function<double>(
         "--refresh",
         [&options](double s) { options.refresh = std::chrono::milliseconds(static_cast<long>(s * 1000)); },
         "seconds between screen updates")
      ->default_str("0.5");
  app.add_flag("--once", options.once, "print one frame to stdout once the fleet is discovered, then exit");
  app.add_option("--iterations", options.iterations, "print this many frames, then exit")
      ->check(CLI::NonNegativeNumber);
  app.add_option_function<double>(
         "--wait",
         [&options](double s) { options.wait = std::chrono::milliseconds(static_cast<long>(s * 1000)); },
         "--once: longest wait for the fleet, seconds")
      ->default_str("5");
  app.add_option("--color", options.color, "auto, always or never")
      ->check(CLI::IsMember({"auto", "always", "never"}))
      ->capture_default_str();
  app.add_option("--width", options.width, "screen width (default: terminal)");
  app.add_option("--height", options.height, "screen height (default: terminal)");
  app.add_option_function<std::string>(
         "--node",
         [&options](const std::string& text) {
           const auto colon = text.rfind(':');
           int id = -1;
           try {
             if (colon != std::string::npos && colon > 0) id = std::stoi(text.substr(colon + 1));
           } catch (const std::exception&) {
           }
           if (id < 0 || id > 127) throw CLI::ValidationError("--node", "BUS:NODE-ID expected, e.g. can0:6");
           options.node = NodeKey{text.substr(0, colon), static_cast<std::uint8_t>(id)};
         },
         "open on this node's detail view (BUS:NODE-ID, e.g. can0:6); with --once print it")
      ->type_name("BUS:ID");
  app.add_option_function<int>(
      "--auto-page", [&options](int s) { options.auto_page = std::chrono::seconds(s); },
      "turn to the next page every N seconds");
}

int RunTop(const TopOptions& options) {
  std::ostream& out = options.out ? *options.out : std::cout;
  const bool to_terminal = options.out == nullptr && isatty(STDOUT_FILENO);
  const bool interactive = !options.once && options.iterations == 0 && to_terminal && isatty(STDIN_FILENO);

  telemetry::Participant participant(options.dds);
  FleetView view(std::chrono::system_clock::now());
  telemetry::FleetReader reader(
      participant, {.node_status = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); },
                    .emcy = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); },
                    .io = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); },
                    .bus_stats = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); },
                    .fault = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); },
                    .verdict = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); },
                    .scenario = [&](const auto& s, const auto& m) { view.Apply(s, m, nullptr); }});

  RenderSettings settings;
  settings.filter = options.filter;
  settings.sort = options.sort;
  settings.reverse = options.reverse;
  settings.color = options.color == "always" || (options.color == "auto" && to_terminal);
  settings.selected = options.node;
  settings.detail = options.node.has_value();
  const auto update_size = [&] {
    settings.width = 132;
    settings.height = 50;
    if (to_terminal) TerminalSize(settings.width, settings.height);
    if (options.width > 0) settings.width = options.width;
    if (options.height > 0) settings.height = options.height;
  };
  update_size();

  g_stop = false;
  auto* previous_int = std::signal(SIGINT, OnTopStopSignal);
  auto* previous_term = std::signal(SIGTERM, OnTopStopSignal);
  struct RestoreSignals {
    decltype(previous_int) i, t;
    ~RestoreSignals() {
      std::signal(SIGINT, i);
      std::signal(SIGTERM, t);
    }
  } restore{previous_int, previous_term};

  if (options.once) {
    // Transient-local status arrives as soon as each publisher is discovered; wait until no new
    // node has appeared for a second (or the wait runs out).
    const auto start = std::chrono::steady_clock::now();
    while (!g_stop && std::chrono::steady_clock::now() - start < options.wait) {
      reader.Wait(std::chrono::milliseconds(100));
      reader.Poll();
      const auto quiet = std::chrono::system_clock::now() - view.last_new_node();
      if (!view.nodes().empty() && quiet > std::chrono::seconds(1)) break;
    }
    reader.Poll();
    settings.now = std::chrono::system_clock::now();
    out << RenderFrame(view, settings) << std::flush;
    if (view.nodes().empty() && view.buses().empty())
      std::cerr << NothingSeenHint("canfleet top", options.dds) << '\n';
    return 0;
  }

  if (!interactive) {
    for (int i = 0; !g_stop && (options.iterations == 0 || i < options.iterations); ++i) {
      const auto next = std::chrono::steady_clock::now() + options.refresh;
      while (!g_stop && std::chrono::steady_clock::now() < next) {
        reader.Wait(
            std::chrono::duration_cast<std::chrono::nanoseconds>(next - std::chrono::steady_clock::now()));
        reader.Poll();
      }
      settings.now = std::chrono::system_clock::now();
      if (to_terminal) out << "\x1b[H\x1b[2J";
      out << RenderFrame(view, settings) << (to_terminal ? "" : "\n") << std::flush;
    }
    return 0;
  }

  RawTerminal terminal;
  Keys keys;
  auto next_page_turn = std::chrono::steady_clock::now() + options.auto_page;
  auto next_frame = std::chrono::steady_clock::now();
  while (!g_stop && !keys.quit) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_frame) {
      reader.Poll();
      update_size();
      settings.now = std::chrono::system_clock::now();
      if (options.auto_page.count() > 0 && now >= next_page_turn) {
        ++settings.page;
        next_page_turn = now + options.auto_page;
      }
      // Clamp the page here so that n/p never run past the ends.
      const int pages =
          PageCount(SelectRows(view, settings.filter, settings.sort, settings.reverse, settings.now).size(),
                    RowsPerPage(settings, StatusLines(view, settings.filter)));
      if (settings.page >= pages) settings.page = options.auto_page.count() > 0 ? 0 : pages - 1;
      if (settings.page < 0) settings.page = 0;
      std::string frame = RenderFrame(view, settings);
      // Clear to end of line on every line, so shorter lines leave no debris; no full clear (flicker).
      std::string screen = "\x1b[H";
      for (std::size_t pos = 0; pos < frame.size();) {
        const std::size_t end = frame.find('\n', pos);
        screen += frame.substr(pos, end - pos) + "\x1b[K";
        if (end == std::string::npos) break;
        screen += "\r\n";
        pos = end + 1;
      }
      screen += "\x1b[J";
      out << screen << std::flush;
      next_frame = now + options.refresh;
    }
    pollfd input{STDIN_FILENO, POLLIN, 0};
    const auto wait =
        std::chrono::duration_cast<std::chrono::milliseconds>(next_frame - std::chrono::steady_clock::now());
    if (poll(&input, 1, static_cast<int>(std::max<long>(0, wait.count()))) > 0) {
      char buffer[64];
      const ssize_t n = read(STDIN_FILENO, buffer, sizeof buffer);
      for (ssize_t i = 0; i < n; ++i)
        HandleKey(buffer[i], keys, settings, view);
      // A terminal writes an escape sequence at once: a read that ends on a lone Esc was the key.
      if (keys.escape == "\x1b") {
        HandleEscape(keys.escape, settings, view);
        keys.escape.clear();
      }
      next_frame = std::chrono::steady_clock::now();  // redraw at once after a key
    }
  }
  return 0;
}

}  // namespace canfleet::tools

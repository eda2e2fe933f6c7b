#include "orchestrator/scenario/judge.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "orchestrator/control/sdo_value.hpp"
#include "vocabulary/nmt_state.hpp"

namespace canfleet::scenario {

const char* OutcomeName(Outcome outcome) {
  switch (outcome) {
    case Outcome::kPassed:
      return "pass";
    case Outcome::kFailed:
      return "FAIL";
    case Outcome::kSkipped:
      return "skip";
    case Outcome::kPending:
      break;
  }
  return "pending";
}

std::string TimeText(TimePoint t, TimePoint origin) {
  char text[32];
  std::snprintf(text, sizeof text, "t=%.3f s", std::chrono::duration<double>(t - origin).count());
  return text;
}

void Judge::Open(TimePoint origin, TimePoint open, TimePoint close) {
  origin_ = origin;
  open_ = open;
  close_ = std::max(open, close);
  opened_ = true;
}

void Judge::Frame(const std::string& bus, const CanFrame& frame, TimePoint time) {
  if (!decided() && InWindow(time)) OnFrame(bus, frame, time);
}

void Judge::Observe(const Sample& sample) {
  if (!decided() && InWindow(sample.time)) OnSample(sample);
}

void Judge::Close() {
  if (!decided() && opened_) OnClose();
}

void Judge::Pass(TimePoint time, std::string detail) {
  if (decided()) return;
  verdict_ = {Outcome::kPassed, time, std::move(detail)};
}

void Judge::Fail(TimePoint time, std::string detail) {
  if (decided()) return;
  verdict_ = {Outcome::kFailed, time, std::move(detail)};
}

namespace {

std::string Hex(std::uint64_t value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%0*llXh", digits, static_cast<unsigned long long>(value));
  return text;
}

/// Hex bytes "05 80 00" (spaces optional) -> bytes. Throws std::invalid_argument.
std::vector<std::uint8_t> ParseHexBytes(const std::string& text, const char* what) {
  std::string digits;
  for (const char c : text)
    if (c != ' ') digits += c;
  if (digits.size() % 2 != 0)
    throw std::invalid_argument(std::string(what) + ": an odd number of hex digits");
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < digits.size(); i += 2) {
    char* end = nullptr;
    const std::string pair = digits.substr(i, 2);
    const long v = std::strtol(pair.c_str(), &end, 16);
    if (end != pair.c_str() + 2)
      throw std::invalid_argument(std::string(what) + ": \"" + text + "\" is not hex bytes");
    out.push_back(static_cast<std::uint8_t>(v));
  }
  return out;
}

std::string HexBytes(const std::uint8_t* data, std::size_t n) {
  return control::HexBytes(std::span<const std::uint8_t>(data, n));
}

bool IsEmcyOf(const CanFrame& frame, std::uint8_t node_id) {
  return !frame.error() && !frame.remote() && !frame.extended() && frame.id == 0x080u + node_id &&
         frame.dlc == 8;
}

bool IsEmcy(const CanFrame& frame) {
  return !frame.error() && !frame.remote() && !frame.extended() && frame.id > 0x080 && frame.id <= 0x0FF &&
         frame.dlc == 8;
}

std::uint16_t EmcyCode(const CanFrame& f) {
  return static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
}

/// "EMCY 8130h (register 11h, data 05 80 00 00 00)".
std::string EmcyText(const CanFrame& f) {
  return "EMCY " + Hex(EmcyCode(f), 4) + " (register " + Hex(f.data[2], 2) + ", data " +
         HexBytes(&f.data[3], 5) + ")";
}

/// Holds a list of what was seen for a failure message: the first few, and how many more.
class Seen {
 public:
  void Add(std::string what) {
    if (items_.size() < kShown) items_.push_back(std::move(what));
    ++count_;
  }
  bool empty() const { return count_ == 0; }
  std::string Text() const {
    std::string out;
    for (const auto& item : items_)
      out += (out.empty() ? "" : "; ") + item;
    if (count_ > items_.size()) out += "; and " + std::to_string(count_ - items_.size()) + " more";
    return out;
  }

 private:
  static constexpr std::size_t kShown = 4;
  std::vector<std::string> items_;
  std::size_t count_ = 0;
};

// ---- EMCY ----

class EmcyJudge final : public Judge {
 public:
  EmcyJudge(const topology::EmcyExpect& e, PortAddress port) : e_(e), port_(std::move(port)) {
    if (!e.manufacturer().empty()) {
      manufacturer_ = ParseHexBytes(e.manufacturer(), "manufacturer");
      if (manufacturer_.size() != 5) throw std::invalid_argument("manufacturer: 5 bytes");
      mask_ = e.manufacturer_mask().empty() ? std::vector<std::uint8_t>(5, 0xFF)
                                            : ParseHexBytes(e.manufacturer_mask(), "manufacturer_mask");
      if (mask_.size() != 5) throw std::invalid_argument("manufacturer_mask: 5 bytes");
    }
  }
  std::string Describe() const override {
    std::string out = "EMCY " + Hex(e_.code(), 4);
    if (e_.has_error_register()) out += " register " + Hex(e_.error_register(), 2);
    if (!manufacturer_.empty()) out += " data " + HexBytes(manufacturer_.data(), 5);
    return out + " from " + port_.node;
  }

 protected:
  void OnFrame(const std::string& bus, const CanFrame& f, TimePoint time) override {
    if (bus != port_.bus || !IsEmcyOf(f, port_.node_id)) return;
    bool match = EmcyCode(f) == e_.code();
    if (e_.has_error_register()) match = match && f.data[2] == e_.error_register();
    for (std::size_t i = 0; i < manufacturer_.size(); ++i)
      match = match && (f.data[3 + i] & mask_[i]) == (manufacturer_[i] & mask_[i]);
    if (match) return Pass(time, "seen " + EmcyText(f) + " at " + T(time));
    seen_.Add(EmcyText(f) + " at " + T(time));
  }
  void OnClose() override {
    Fail(close(), seen_.empty() ? "no EMCY from " + port_.node + " in the window" : "saw " + seen_.Text());
  }

 private:
  topology::EmcyExpect e_;
  PortAddress port_;
  std::vector<std::uint8_t> manufacturer_, mask_;
  Seen seen_;
};

class NoEmcyJudge final : public Judge {
 public:
  NoEmcyJudge(const topology::NoEmcyExpect& e, std::optional<PortAddress> port, NodeNamer namer)
      : e_(e), port_(std::move(port)), namer_(std::move(namer)) {}
  std::string Describe() const override {
    return std::string("no EMCY") + (e_.has_code() ? " " + Hex(e_.code(), 4) : "") + " from " +
           (port_ ? port_->node : "any node");
  }

 protected:
  void OnFrame(const std::string& bus, const CanFrame& f, TimePoint time) override {
    if (port_ ? (bus != port_->bus || !IsEmcyOf(f, port_->node_id)) : !IsEmcy(f)) return;
    if (e_.has_code() && EmcyCode(f) != e_.code()) return;
    const auto id = static_cast<std::uint8_t>(f.id - 0x080);
    std::string who = namer_ ? namer_(bus, id) : "";
    if (who.empty()) who = bus + " node-ID " + std::to_string(id);
    Fail(time, "saw " + EmcyText(f) + " from " + who + " at " + T(time));
  }
  void OnClose() override { Pass(close(), "none seen"); }

 private:
  topology::NoEmcyExpect e_;
  std::optional<PortAddress> port_;
  NodeNamer namer_;
};

// ---- states: NMT, SDO, I/O, controller ----

/// A state that must be seen at some observation of the window, or at every one (throughout).
class StateJudge : public Judge {
 public:
  explicit StateJudge(bool throughout) : throughout_(throughout) {}

 protected:
  /// Judges one observation: whether it matches, and how to show it ("pre-operational").
  void Judged(TimePoint time, bool match, const std::string& shown) {
    ++observations_;
    const std::string at = shown + " at " + T(time);
    if (throughout_) {
      if (!match) return Fail(time, "was " + at);
      first_ = first_.empty() ? at : first_;
      last_ = at;
    } else {
      if (match) return Pass(time, at);
      seen_.Add(at);
    }
    if (instant()) OnClose();  // judged on its first observation
  }
  void OnClose() override {
    if (observations_ == 0) return Fail(close(), "nothing observed in the window" + Why());
    if (throughout_) return Pass(close(), observations_ == 1 ? first_ : "from " + first_ + " to " + last_);
    Fail(close(), "was " + seen_.Text());
  }
  /// Why nothing could be observed (a read that did not complete), for the message.
  virtual std::string Why() const { return ""; }

 private:
  bool throughout_;
  std::size_t observations_ = 0;
  Seen seen_;
  std::string first_, last_;
};

/// The state of a heartbeat or guarding reply (bit 7: the guarding toggle bit).
const char* NmtName(std::uint8_t state) {
  return canopen::ToString(static_cast<canopen::NmtState>(state & 0x7F));
}

class NmtJudge final : public StateJudge {
 public:
  NmtJudge(const topology::NmtExpect& e, bool throughout, PortAddress port)
      : StateJudge(throughout), e_(e), port_(std::move(port)) {}
  Poll Needs() const override { return Poll::kNmt; }
  std::string Describe() const override { return port_.node + " " + e_.state(); }

 protected:
  void OnFrame(const std::string& bus, const CanFrame& f, TimePoint time) override {
    // CiA 301 §7.2.8.3.2: heartbeat 700h + node-ID, one byte, the state (bit 7: guarding toggle).
    if (bus != port_.bus || f.error() || f.remote() || f.extended() || f.id != 0x700u + port_.node_id ||
        f.dlc != 1)
      return;
    const std::string state = NmtName(f.data[0]);
    Judged(time, state == e_.state(), state + " (heartbeat)");
  }
  void OnSample(const Sample& s) override {
    if (!s.error.empty()) return;
    Judged(s.time, s.text == e_.state(), s.text);
  }

 private:
  topology::NmtExpect e_;
  PortAddress port_;
};

bool IsIntegerType(control::SdoType type) {
  const std::size_t size = control::SdoTypeSize(type);
  const std::string_view name = control::SdoTypeName(type);
  return size > 0 && !name.empty() && (name[0] == 'u' || name[0] == 'i');
}

std::uint64_t LittleEndian(const std::vector<std::uint8_t>& data) {
  std::uint64_t v = 0;
  for (std::size_t i = std::min<std::size_t>(data.size(), 8); i-- > 0;)
    v = (v << 8) | data[i];
  return v;
}

class SdoJudge final : public StateJudge {
 public:
  SdoJudge(const topology::SdoExpect& e, bool throughout, PortAddress port)
      : StateJudge(throughout), e_(e), port_(std::move(port)), type_(control::RequireSdoType(e.type())) {
    if (!e.has_abort()) expected_ = control::EncodeSdoValue(type_, e.value());
    if (e.has_mask() && !IsIntegerType(type_)) throw std::invalid_argument("mask: an integer type only");
  }
  Poll Needs() const override { return Poll::kSdo; }
  std::string Describe() const override {
    std::string out = port_.node + " " + Hex(e_.index(), 4) + " sub " + std::to_string(e_.subindex());
    if (e_.has_abort()) return out + " aborts " + Hex(e_.abort(), 8);
    out += " = " + e_.value();
    if (e_.has_mask()) out += " (mask " + Hex(e_.mask(), 1) + ")";
    return out;
  }

 protected:
  void OnSample(const Sample& s) override {
    if (!s.error.empty()) {
      why_ = s.error;
      return Judged(s.time, false, s.error);
    }
    if (s.abort) {
      char text[48];
      std::snprintf(text, sizeof text, "SDO abort %08Xh", *s.abort);
      return Judged(s.time, e_.has_abort() && *s.abort == e_.abort(), text);
    }
    if (e_.has_abort()) return Judged(s.time, false, Show(s.data));
    bool match;
    if (e_.has_mask())
      match = (LittleEndian(s.data) & e_.mask()) == (LittleEndian(expected_) & e_.mask());
    else
      match = s.data == expected_;
    Judged(s.time, match, Show(s.data));
  }
  std::string Why() const override { return why_.empty() ? "" : " (" + why_ + ")"; }

 private:
  std::string Show(const std::vector<std::uint8_t>& data) const {
    std::string text;
    try {
      text = control::FormatSdoValue(type_, data);
    } catch (const std::exception&) {
      return control::HexBytes(data);
    }
    if (IsIntegerType(type_)) {
      const int digits = static_cast<int>(2 * control::SdoTypeSize(type_));
      std::uint64_t v = LittleEndian(data);
      if (e_.has_mask()) return text + " (" + Hex(v, digits) + ", masked " + Hex(v & e_.mask(), digits) + ")";
      return text + " (" + Hex(v, digits) + ")";
    }
    return text;
  }

  topology::SdoExpect e_;
  PortAddress port_;
  control::SdoType type_;
  std::vector<std::uint8_t> expected_;
  std::string why_;
};

/// The leading number of a value text ("1000", "24.0"); nullopt when it is not one.
std::optional<double> Number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string NumberText(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

class IoJudge final : public StateJudge {
 public:
  IoJudge(const topology::IoExpect& e, bool throughout, std::string node)
      : StateJudge(throughout), e_(e), node_(std::move(node)) {}
  Poll Needs() const override { return Poll::kIo; }
  std::string Describe() const override {
    std::string out = node_ + " " + e_.name();
    if (!e_.value().empty()) return out + " = " + e_.value();
    if (e_.has_min() && e_.has_max())
      return out + " in " + NumberText(e_.min()) + ".." + NumberText(e_.max());
    if (e_.has_min()) return out + " >= " + NumberText(e_.min());
    return out + " <= " + NumberText(e_.max());
  }

 protected:
  void OnSample(const Sample& s) override {
    if (!s.error.empty()) {
      why_ = s.error;
      return Judged(s.time, false, s.error);
    }
    const std::optional<double> v = Number(s.text);
    bool match;
    if (!e_.value().empty()) {
      const std::optional<double> want = Number(e_.value());
      const double tolerance = e_.tolerance() > 0 ? e_.tolerance() : 0.5;
      match = want && v ? std::fabs(*v - *want) <= tolerance : s.text == e_.value();
    } else {
      match = v && (!e_.has_min() || *v >= e_.min()) && (!e_.has_max() || *v <= e_.max());
    }
    Judged(s.time, match, s.text + (s.unit.empty() ? "" : " " + s.unit));
  }
  std::string Why() const override { return why_.empty() ? "" : " (" + why_ + ")"; }

 private:
  topology::IoExpect e_;
  std::string node_;
  std::string why_;
};

class ControllerJudge final : public StateJudge {
 public:
  ControllerJudge(const topology::ControllerExpect& e, bool throughout, PortAddress port)
      : StateJudge(throughout), e_(e), port_(std::move(port)) {}
  Poll Needs() const override { return Poll::kController; }
  std::string Describe() const override { return port_.node + " on " + port_.bus + " " + e_.state(); }

 protected:
  void OnSample(const Sample& s) override {
    if (s.error.empty()) Judged(s.time, s.text == e_.state(), s.text);
  }

 private:
  topology::ControllerExpect e_;
  PortAddress port_;
};

// ---- frames and the bus ----

class FramesJudge final : public Judge {
 public:
  FramesJudge(const topology::FramesExpect& e, std::string bus) : e_(e), bus_(std::move(bus)) {
    mask_ = e.has_mask() ? e.mask() : (e.extended() ? 0x1FFFFFFFu : 0x7FFu);
    if (!e.data().empty()) {
      data_ = ParseHexBytes(e.data(), "data");
      data_mask_ = e.data_mask().empty() ? std::vector<std::uint8_t>(data_.size(), 0xFF)
                                         : ParseHexBytes(e.data_mask(), "data_mask");
      if (data_mask_.size() != data_.size()) throw std::invalid_argument("data_mask: as many bytes as data");
    }
  }
  std::string Describe() const override {
    std::string out = Hex(e_.cob_id(), 3);
    if (e_.has_mask()) out += "/" + Hex(e_.mask(), 3);
    out += " on " + bus_;
    if (e_.has_at_most() && e_.at_most() == 0) return out + " not seen";
    if (e_.has_at_least()) out += " at least " + std::to_string(e_.at_least()) + "x";
    if (e_.has_at_most()) out += " at most " + std::to_string(e_.at_most()) + "x";
    if (e_.period_ms() > 0)
      out += " every " + std::to_string(e_.period_ms()) + " +- " + std::to_string(e_.tolerance_ms()) + " ms";
    if (!data_.empty()) out += " data " + control::HexBytes(data_);
    return out;
  }

 protected:
  void OnFrame(const std::string& bus, const CanFrame& f, TimePoint time) override {
    if (bus != bus_ || f.error() || f.extended() != e_.extended() || (f.id & mask_) != (e_.cob_id() & mask_))
      return;
    ++count_;
    const std::string frame_text = Hex(f.id, f.extended() ? 8 : 3) + "#" + HexBytes(f.data.data(), f.dlc);
    if (e_.has_at_most() && count_ > e_.at_most())
      return Fail(time, "seen " + std::to_string(count_) + "x, the last " + frame_text + " at " + T(time));
    if (!data_.empty()) {
      bool match = f.dlc >= data_.size();
      for (std::size_t i = 0; match && i < data_.size(); ++i)
        match = (f.data[i] & data_mask_[i]) == (data_[i] & data_mask_[i]);
      if (!match) return Fail(time, "saw " + frame_text + " at " + T(time));
    }
    if (e_.period_ms() > 0) {
      const TimePoint from = last_ ? *last_ : open();
      if (!GapOk(time - from, last_.has_value()))
        return Fail(time, GapText(time - from) +
                              (last_ ? " between two frames" : " from the window's start") + ", up to " +
                              T(time));
      if (last_) {
        shortest_ = std::min(shortest_, time - *last_);
        longest_ = std::max(longest_, time - *last_);
      }
    }
    last_ = time;
    last_text_ = frame_text;
    // Only a count to reach: decided now.
    if (e_.has_at_least() && count_ >= e_.at_least() && !e_.has_at_most() && e_.period_ms() == 0 &&
        data_.empty())
      Pass(time, "seen " + std::to_string(count_) + "x by " + T(time));
  }
  void OnClose() override {
    const std::string counted = "seen " + std::to_string(count_) + "x";
    if (e_.has_at_least() && count_ < e_.at_least()) return Fail(close(), counted);
    if ((e_.period_ms() > 0 || !data_.empty()) && count_ == 0) return Fail(close(), "none seen");
    if (e_.period_ms() > 0 && last_ && !GapOk(close() - *last_, false))
      return Fail(close(), GapText(close() - *last_) + " since the last one at " + T(*last_));
    std::string detail = counted;
    if (e_.period_ms() > 0 && count_ > 1) detail += ", gaps " + Ms(shortest_) + ".." + Ms(longest_) + " ms";
    if (!last_text_.empty()) detail += ", the last " + last_text_;
    Pass(close(), detail);
  }

 private:
  /// A gap between two frames is the period +- tolerance; one from the window's start or to its
  /// end only must not exceed period + tolerance.
  bool GapOk(Duration gap, bool between) const {
    const auto period = std::chrono::milliseconds(e_.period_ms());
    const auto tolerance = std::chrono::milliseconds(e_.tolerance_ms());
    return gap <= period + tolerance && (!between || gap >= period - tolerance);
  }
  static std::string Ms(Duration d) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", std::chrono::duration<double, std::milli>(d).count());
    return text;
  }
  static std::string GapText(Duration d) { return "a gap of " + Ms(d) + " ms"; }

  topology::FramesExpect e_;
  std::string bus_;
  std::uint32_t mask_ = 0x7FF;
  std::vector<std::uint8_t> data_, data_mask_;
  std::uint64_t count_ = 0;
  std::optional<TimePoint> last_;
  std::string last_text_;
  Duration shortest_ = Duration::max(), longest_ = Duration::zero();
};

class BusJudge final : public Judge {
 public:
  BusJudge(const topology::BusExpect& e, std::string bus) : e_(e), bus_(std::move(bus)) {}
  Poll Needs() const override { return e_.no_error_frames() ? Poll::kNone : Poll::kBusLoad; }
  std::string Describe() const override {
    if (e_.has_load_below()) return bus_ + " load below " + NumberText(e_.load_below()) + "%";
    if (e_.has_load_above()) return bus_ + " load above " + NumberText(e_.load_above()) + "%";
    return "no error frames on " + bus_;
  }

 protected:
  void OnFrame(const std::string& bus, const CanFrame& f, TimePoint time) override {
    if (e_.no_error_frames() && bus == bus_ && f.error())
      Fail(time, "an error frame (" + Hex(f.id, f.extended() ? 8 : 3) + ") at " + T(time));
  }
  void OnSample(const Sample& s) override {
    if (!s.error.empty() || e_.no_error_frames()) return;
    ++samples_;
    if (s.load_percent >= highest_) {
      highest_ = s.load_percent;
      highest_at_ = s.time;
    }
    if (e_.has_load_below() && s.load_percent >= e_.load_below())
      return Fail(s.time, "load " + Percent(s.load_percent) + " at " + T(s.time));
    if (e_.has_load_above() && s.load_percent > e_.load_above())
      return Pass(s.time, "load " + Percent(s.load_percent) + " at " + T(s.time));
  }
  void OnClose() override {
    if (e_.no_error_frames()) return Pass(close(), "none seen");
    if (samples_ == 0) return Fail(close(), "no sample of the bus load in the window");
    const std::string highest = "highest load " + Percent(highest_) + " at " + T(highest_at_);
    if (e_.has_load_below()) return Pass(close(), highest);
    Fail(close(), highest);
  }

 private:
  static std::string Percent(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f%%", v);
    return text;
  }
  topology::BusExpect e_;
  std::string bus_;
  std::size_t samples_ = 0;
  double highest_ = 0;
  TimePoint highest_at_{};
};

}  // namespace

std::unique_ptr<Judge> MakeJudge(const topology::Expect& expect, const std::optional<PortAddress>& port,
                                 const std::string& bus, NodeNamer namer) {
  using E = topology::Expect;
  auto need_port = [&]() -> PortAddress {
    if (!port) throw std::invalid_argument("the expectation names no node");
    return *port;
  };
  switch (expect.what_case()) {
    case E::kEmcy:
      return std::make_unique<EmcyJudge>(expect.emcy(), need_port());
    case E::kNoEmcy:
      return std::make_unique<NoEmcyJudge>(expect.no_emcy(), port, std::move(namer));
    case E::kNmt:
      return std::make_unique<NmtJudge>(expect.nmt(), expect.throughout(), need_port());
    case E::kSdo:
      return std::make_unique<SdoJudge>(expect.sdo(), expect.throughout(), need_port());
    case E::kIo:
      return std::make_unique<IoJudge>(expect.io(), expect.throughout(), need_port().node);
    case E::kFrames:
      return std::make_unique<FramesJudge>(expect.frames(), bus);
    case E::kBus:
      return std::make_unique<BusJudge>(expect.bus(), bus);
    case E::kController:
      return std::make_unique<ControllerJudge>(expect.controller(), expect.throughout(), need_port());
    case E::WHAT_NOT_SET:
      break;
  }
  throw std::invalid_argument("an expectation needs a kind");
}

}  // namespace canfleet::scenario

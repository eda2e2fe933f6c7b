#include "tests/unit/datalogger/datalogger_fixture.hpp"

#include <unistd.h>

#include <cstdio>

#include "node/devices/datalogger_tc_analog/datalogger_objects.hpp"

namespace canfleet::devices::test {

std::string Cob(std::uint32_t cob_id) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%03X#", static_cast<unsigned>(cob_id));
  return buf;
}

std::string Emcy(std::uint8_t node, std::uint16_t code, std::uint8_t reg, std::uint8_t channel,
                 std::uint8_t description) {
  return Cob(0x80u + node) + LeHex(code, 2) + LeHex(reg, 1) + LeHex(channel, 1) + LeHex(description, 1) +
         "000000";
}

std::string EmcyReset(std::uint8_t node, std::uint8_t reg) {
  return Cob(0x80u + node) + "0000" + LeHex(reg, 1) + "0000000000";
}

DataLoggerTest::DataLoggerTest(std::filesystem::path state_dir)
    : state_dir_(std::move(state_dir)),
      port1_(bus1_.Attach("logger-can1")),
      port2_(bus2_.Attach("logger-can2")),
      can1_(bus1_, "master1"),
      can2_(bus2_, "master2") {
  Boot();
}

DataLoggerTest::~DataLoggerTest() {
  node_.reset();
}

void DataLoggerTest::Boot() {
  node_.reset();
  node_ = std::make_unique<DeviceNode>(
      std::make_unique<DataLogger>(DeviceOptions{.eds = {}, .ports = 2}), scheduler_,
      std::vector<BusPort*>{&port1_, &port2_},
      NodeSettings{{PortSettings{kNode1, 4}, PortSettings{kNode2, 4}}, state_dir_, std::nullopt, {}});
  node_->Start();
  backlog_[0].clear();
  backlog_[1].clear();
  EXPECT_EQ(can1_.Take(), std::vector<std::string>{"705#00"});
  EXPECT_EQ(can2_.Take(), std::vector<std::string>{"706#00"});
}

void DataLoggerTest::Start(int port) {
  Send(port, "000#01" + LeHex(kNodes[static_cast<std::size_t>(port)], 1));
}

std::vector<std::string> DataLoggerTest::Frames(int port) {
  auto& backlog = backlog_[static_cast<std::size_t>(port)];
  std::vector<std::string> out(backlog.begin(), backlog.end());
  backlog.clear();
  for (auto& f : Probe(port).Take())
    out.push_back(std::move(f));
  return out;
}

std::vector<std::string> DataLoggerTest::Frames(int port, std::string_view prefix) {
  std::vector<std::string> out;
  for (auto& f : Frames(port)) {
    if (f.starts_with(prefix)) out.push_back(std::move(f));
  }
  return out;
}

std::string DataLoggerTest::Sdo(int port, std::string_view request) {
  auto& backlog = backlog_[static_cast<std::size_t>(port)];
  for (auto& f : Probe(port).Take())
    backlog.push_back(std::move(f));
  Probe(port).Send(request);
  const std::string response = Cob(0x580u + kNodes[static_cast<std::size_t>(port)]);
  std::string answer;
  for (auto& f : Probe(port).Take()) {
    if (answer.empty() && f.starts_with(response))
      answer = std::move(f);
    else
      backlog.push_back(std::move(f));
  }
  return answer;
}

std::string DataLoggerTest::TryWrite(int port, std::uint16_t index, std::uint8_t sub, std::uint64_t value,
                                     int size) {
  return Sdo(port, SdoWrite(kNodes[static_cast<std::size_t>(port)], index, sub, value, size));
}

void DataLoggerTest::Write(int port, std::uint16_t index, std::uint8_t sub, std::uint64_t value, int size) {
  EXPECT_EQ(TryWrite(port, index, sub, value, size),
            SdoWritten(kNodes[static_cast<std::size_t>(port)], index, sub));
}

std::int64_t DataLoggerTest::Read(int port, std::uint16_t index, std::uint8_t sub, bool is_signed) {
  const std::string answer = Sdo(port, SdoRead(kNodes[static_cast<std::size_t>(port)], index, sub));
  EXPECT_EQ(answer.size(), 4u + 16u) << answer;
  if (answer.size() != 20) return 0;
  const std::string cmd = answer.substr(4, 2);
  const int size = cmd == "4F" ? 1 : cmd == "4B" ? 2 : cmd == "47" ? 3 : cmd == "43" ? 4 : 0;
  EXPECT_NE(size, 0) << answer;
  std::uint64_t value = 0;
  for (int i = 0; i < size; ++i)
    value |= std::stoull(answer.substr(static_cast<std::size_t>(12 + 2 * i), 2), nullptr, 16) << (8 * i);
  if (is_signed && size > 0 && size < 8 && ((value >> (8 * size - 1)) & 1))
    value |= ~std::uint64_t{0} << (8 * size);
  return static_cast<std::int64_t>(value);
}

std::vector<std::uint32_t> DataLoggerTest::ErrorField(int port) {
  std::vector<std::uint32_t> out;
  const auto count = Read(port, 0x1003, 0);
  for (std::int64_t i = 1; i <= count; ++i)
    out.push_back(static_cast<std::uint32_t>(Read(port, 0x1003, static_cast<std::uint8_t>(i))));
  return out;
}

void DataLoggerTest::ConfigureTcLimitsAway() {
  for (std::uint8_t sub = 1; sub <= 4; ++sub) {
    Write(0, datalogger::kTcLowWarning, sub, static_cast<std::uint16_t>(-400), 2);
    Write(0, datalogger::kTcHighWarning, sub, 6000, 2);
    Write(0, datalogger::kTcLowShutdown, sub, static_cast<std::uint16_t>(-500), 2);
    Write(0, datalogger::kTcHighShutdown, sub, 7000, 2);
  }
  Advance(20ms);
  Frames(0);
  Frames(1);
}

void DataLoggerTest::SilenceTpdos() {
  for (int port = 0; port < 2; ++port) {
    for (std::uint16_t index = 0x1800; index <= 0x1802; ++index)
      Write(port, index, 5, 0, 2);
  }
}

DataLoggerStorageTest::DataLoggerStorageTest() : DataLoggerTest(MakeDir()) {}

DataLoggerStorageTest::~DataLoggerStorageTest() {
  node_.reset();
  std::filesystem::remove_all(state_dir_);
}

std::filesystem::path DataLoggerStorageTest::MakeDir() {
  auto dir = std::filesystem::temp_directory_path() /
             ("canfleet-datalogger-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace canfleet::devices::test

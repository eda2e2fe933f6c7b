// `canfleet` commands against a scripted control API server (tools/canfleet/README.md).
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>

#include <asio/executor_work_guard.hpp>
#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <thread>

#include "orchestrator/control/control_server.hpp"
#include "tests/system/support/child_process.hpp"

namespace canfleet::control {
namespace {

using namespace std::chrono_literals;
using system_test::ChildProcess;
using system_test::kPatience;
using system_test::TempDir;
using system_test::WaitUntil;

template <class M>
M Parse(const std::string& text) {
  M message;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &message)) << text;
  return message;
}

bool Same(const google::protobuf::Message& a, const google::protobuf::Message& b) {
  return google::protobuf::util::MessageDifferencer::Equals(a, b);
}

/// Records every request and answers it with what the test scripted: a Response body built by
/// `answer` (its id is filled in), or nothing at all when `answer` is empty.
class ScriptedHandler final : public ControlHandler {
 public:
  using Answer = std::function<Response(const Request&)>;

  void Handle(const Request& request, std::shared_ptr<Responder> responder) override {
    Answer answer;
    {
      std::lock_guard lock(mutex_);
      requests_.push_back(request);
      answer = answer_;
    }
    if (request.has_dump() && stream_) {
      stream_(request, responder);
      return;
    }
    if (!answer) {
      held_.push_back(responder);  // never answered
      return;
    }
    Response response = answer(request);
    response.set_id(request.id());
    responder->Send(response);
  }

  void SetAnswer(Answer answer) {
    std::lock_guard lock(mutex_);
    answer_ = std::move(answer);
  }
  /// Dump requests go here instead (on the io thread).
  std::function<void(const Request&, std::shared_ptr<Responder>)> stream_;

  std::vector<Request> Requests() {
    std::lock_guard lock(mutex_);
    return requests_;
  }
  void Release() { held_.clear(); }

 private:
  std::mutex mutex_;
  std::vector<Request> requests_;
  Answer answer_;
  std::vector<std::shared_ptr<Responder>> held_;
};

Response Done(const std::string& detail) {
  Response r;
  r.mutable_done()->set_detail(detail);
  return r;
}

Response Error(const std::string& error) {
  Response r;
  r.set_error(error);
  return r;
}

struct Outcome {
  std::optional<int> exit;
  std::string out;  ///< stdout, lines joined with '\n' (each line ends with one)
  std::string err;
};

class CanfleetCli : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = std::make_unique<ControlServer>(io_, handler_);
    const auto ep = server_->Listen("tcp://127.0.0.1:0");
    endpoint_ = "tcp://127.0.0.1:" + std::to_string(ep.port());
    thread_ = std::thread([this] { io_.run(); });
  }

  void TearDown() override {
    OnIo([this] {
      server_->Close();
      handler_.Release();
      handler_.stream_ = nullptr;
    });
    work_.reset();
    thread_.join();
  }

  template <class F>
  void OnIo(F f) {
    std::packaged_task<void()> task(std::move(f));
    auto done = task.get_future();
    asio::post(io_, [&task] { task(); });
    done.get();
  }

  std::vector<std::string> Argv(const std::vector<std::string>& args, bool with_control = true) {
    std::vector<std::string> argv{PROGRAM_CANFLEET};
    if (with_control) argv.insert(argv.end(), {"--control", endpoint_});
    argv.insert(argv.end(), args.begin(), args.end());
    return argv;
  }

  /// Runs canfleet with `args` (after --control) to its end.
  Outcome Canfleet(const std::vector<std::string>& args, bool with_control = true) {
    ChildProcess child(Argv(args, with_control), dir_.File("stderr-" + std::to_string(++runs_)));
    return Finish(child);
  }

  static Outcome Finish(ChildProcess& child) {
    Outcome run;
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (child.Running() && std::chrono::steady_clock::now() < deadline) {
      child.Poll();  // a full pipe would block the child
      std::this_thread::sleep_for(2ms);
    }
    run.exit = child.Wait(1ms);
    child.WaitForLine([](const std::string&) { return false; }, 2s);  // the rest, to EOF
    for (const auto& line : child.Lines())
      run.out += line + "\n";
    run.err = child.Log();
    return run;
  }

  /// The one request the last command sent.
  Request OnlyRequest() {
    const auto requests = handler_.Requests();
    EXPECT_EQ(requests.size(), 1u);
    return requests.empty() ? Request() : requests.back();
  }

  asio::io_context io_;
  asio::executor_work_guard<asio::io_context::executor_type> work_ = asio::make_work_guard(io_);
  ScriptedHandler handler_;
  std::unique_ptr<ControlServer> server_;
  std::string endpoint_;
  std::thread thread_;
  TempDir dir_;
  int runs_ = 0;
};

const char* const kStatus = R"pb(
  topology: "demo"
  uptime_s: 187.4
  buses {
    name: "can0"
    bitrate: 250000
    paced: true
    ports: 4
    load_percent: 12.5
    frames_per_s: 341
    error_frames_per_s: 0
    frames: 10234
    error_frames: 0
  }
  buses {
    name: "can1"
    bitrate: 1000000
    paced: false
    ports: 2
    load_percent: 0
    frames_per_s: 0
    error_frames: 3
  }
  nodes {
    name: "quad-5"
    device: "quad-controller"
    node_ids: 5
    buses: "can0"
    process: "running"
    pid: 4242
    attached: true
    booted: true
    nmt_state: "operational"
    heartbeat_age_s: 0.21
    controller: "error-active"
    tec: 0
    rec: 0
  }
  nodes {
    name: "psu-1"
    device: "power-supply-24v"
    node_ids: 10
    node_ids: 11
    buses: "can0"
    buses: "can1"
    process: "exited"
    detail: "signal 9"
    restarts: 2
    nmt_state: "unknown"
    heartbeat_age_s: -1
    controller: "error-passive"
    tec: 136
    rec: 3
    last_emcy { code: 0x8130 register: 0x11 time_s: 12.34 }
    emcy_count: 3
  }
  faults {
    fault_id: 1
    state: "active"
    started_s: 100.5
    hits: 34
    summary: "heartbeat-loss of quad-5 on can0 (to all receivers), until cleared"
    spec { kind: HEARTBEAT_LOSS node: "quad-5" label: "hb" }
  }
)pb";

TEST_F(CanfleetCli, StatusPrintsBusesNodesAndActiveFaults) {
  handler_.SetAnswer([](const Request&) {
    Response r;
    *r.mutable_status() = Parse<Status>(kStatus);
    return r;
  });
  const Outcome run = Canfleet({"status"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(OnlyRequest().has_status());
  EXPECT_EQ(run.out,
            "topology demo, up 3m07s\n"
            "\n"
            "BUS        BITRATE   LOAD  FRAMES/S  ERRORS/S  FRAMES  ERRORS  PORTS\n"
            "can0          250k  12.5%     341.0       0.0   10234       0      4\n"
            "can1  1M (unpaced)   0.0%       0.0       0.0       0       3      2\n"
            "\n"
            "NODE    DEVICE               ID  BUS        PROCESS                         PID  NMT          "
            "CONTROLLER     TEC  REC  HEARTBEAT  LAST EMCY\n"
            "quad-5  quad-controller       5  can0       running                        4242  operational  "
            "error-active     0    0       0.2s  -\n"
            "psu-1   power-supply-24v  10,11  can0,can1  exited (signal 9), 2 restarts     -  unknown      "
            "error-passive  136    3          -  8130h reg 11h at 12.3s (3 total)\n"
            "\n"
            "FAULT  STATE   STARTED  ENDED  HITS  LABEL  SUMMARY\n"
            "    1  active   100.5s      -    34  hb     heartbeat-loss of quad-5 on can0 (to all "
            "receivers), until "
            "cleared\n");
}

TEST_F(CanfleetCli, StatusJsonIsTheStatusMessage) {
  const Status status = Parse<Status>(kStatus);
  handler_.SetAnswer([&status](const Request&) {
    Response r;
    *r.mutable_status() = status;
    return r;
  });
  const Outcome run = Canfleet({"status", "--json"});
  ASSERT_EQ(run.exit, 0) << run.err;
  Status parsed;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(run.out, &parsed).ok()) << run.out;
  EXPECT_TRUE(Same(parsed, status)) << run.out;
  EXPECT_NE(run.out.find("\"load_percent\": 12.5"), std::string::npos) << "field names as in the .proto";
  EXPECT_NE(run.out.find("\"error_frames_per_s\": 0"), std::string::npos) << "zero fields are printed too";
  EXPECT_NE(run.out.find("\"frames\": 10234,"), std::string::npos) << "64-bit counters are JSON numbers";
}

TEST_F(CanfleetCli, AnOrchestratorErrorExitsWithOneAndItsMessage) {
  handler_.SetAnswer([](const Request&) { return Error("unknown node 'quad-9'"); });
  const Outcome run = Canfleet({"io", "get", "quad-9"});
  EXPECT_EQ(run.exit, 1);
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(run.err, "canfleet: unknown node 'quad-9'\n");
}

TEST_F(CanfleetCli, NoOrchestratorExitsWithOneAndSaysWhereItLooked) {
  const std::string nowhere = "tcp://127.0.0.1:" + std::to_string(system_test::FreeTcpPort());
  const Outcome run = Canfleet({"--control", nowhere, "status"}, false);
  EXPECT_EQ(run.exit, 1);
  EXPECT_EQ(run.err, "canfleet: no orchestrator at " + nowhere + " (is `canfleet up` running?)\n");
}

TEST_F(CanfleetCli, TheControlEndpointComesFromTheEnvironmentToo) {
  handler_.SetAnswer([](const Request&) { return Done("cleared 2 faults"); });
  ::setenv("CANFLEET_CONTROL", endpoint_.c_str(), 1);
  const Outcome run = Canfleet({"fault", "clear", "--all"}, false);
  ::unsetenv("CANFLEET_CONTROL");
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "cleared 2 faults\n");
}

TEST_F(CanfleetCli, GlobalOptionsMayFollowTheSubcommand) {
  handler_.SetAnswer([](const Request&) { return Done("shutting down"); });
  const Outcome run = Canfleet({"down", "--control", endpoint_}, false);
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(OnlyRequest().has_shutdown());
  EXPECT_EQ(run.out, "shutting down\n");
}

TEST_F(CanfleetCli, NoAnswerWithinTimeoutExitsWithOne) {
  handler_.SetAnswer(nullptr);
  const Outcome run = Canfleet({"--timeout", "200ms", "status"});
  EXPECT_EQ(run.exit, 1);
  EXPECT_EQ(run.err, "canfleet: no response from the orchestrator at " + endpoint_ + " within 200ms\n");
}

TEST_F(CanfleetCli, BadArgumentsExitWithTwoAndSendNothing) {
  const std::vector<std::vector<std::string>> kBad = {
      {},
      {"frobnicate"},
      {"fault", "inject", "heartbeat"},
      {"fault", "inject", "delay", "--delay", "10"},
      {"fault", "inject", "drop", "--cob-id", "185"},
      {"fault", "inject", "drop", "--cob-id", "0x800"},  // 11-bit unless --extended
      {"fault", "inject", "drop", "--probability", "1.5"},
      {"fault", "clear"},
      {"fault", "clear", "3", "--all"},
      {"sdo", "read", "quad-5", "1017", "0"},
      {"sdo", "read", "quad-5", "0x10000", "0"},
      {"sdo", "read", "quad-5", "0x1017", "256"},
      {"sdo", "read", "quad-5", "0x1017", "0", "u7"},
      {"sdo", "write", "quad-5", "0x1017", "0", "u16", "70000"},
      {"sdo", "write", "quad-5", "0x1017", "0", "u16"},
      {"capture", "start", "--bus", "can0"},
      {"capture", "start", "--bus", "can0", "--file", "x", "--format", "pcapng"},
      {"--timeout", "5", "status"},
      {"nmt", "jump"},
      {"fault", "inject", "kill", "quad-5", "--node", "quad-6"},
      {"fault", "inject", "bus-of", "quad-5"},
      {"dump", "can0", "--bus", "can1"},
      {"sdo", "read", "datalogger", "0x1017", "0", "--port", "0"},
      {"sdo", "read", "datalogger", "0x1017", "0", "--port", "CAN0"},
      {"sdo", "write", "datalogger", "0x1017", "0", "u16", "1", "--port", "two"},
      {"io", "set", "quad-5", "IN1.voltage_mV"},
      {"io", "get"},
      {"status", "--jsn"},
  };
  for (const auto& args : kBad) {
    std::string joined;
    for (const auto& a : args)
      joined += a + " ";
    SCOPED_TRACE(joined);
    const Outcome run = Canfleet(args);
    EXPECT_EQ(run.exit, 2) << run.out << run.err;
    EXPECT_FALSE(run.err.empty());
  }
  EXPECT_TRUE(handler_.Requests().empty());
}

TEST_F(CanfleetCli, BadArgumentMessagesSayWhatToWrite) {
  Outcome run = Canfleet({"sdo", "write", "quad-5", "0x1017", "0", "u16", "70000"});
  EXPECT_EQ(run.err, "canfleet: u16 value \"70000\" is out of range (0..65535)\n");
  run = Canfleet({"sdo", "read", "quad-5", "1017", "0"});
  EXPECT_NE(run.err.find("\"1017\" is ambiguous: write it in hex as 0x1017 or 1017h"), std::string::npos)
      << run.err;
  run = Canfleet({"fault", "inject", "delay", "--delay", "10"});
  EXPECT_NE(run.err.find("duration \"10\": missing unit (e.g. 500ms, 2s, 1.5s, 1m)"), std::string::npos)
      << run.err;
  run = Canfleet({"fault", "clear"});
  EXPECT_NE(run.err.find("say which fault: an ID, --label LABEL or --all"), std::string::npos) << run.err;
}

// The ports as the manuals print them (CAN1, CAN2): 0 used to be the first port and is refused
// with the reason rather than guessed.
TEST_F(CanfleetCli, PortsAreCan1AndCan2AndZeroIsRefusedWithTheReason) {
  const Outcome run = Canfleet({"sdo", "read", "datalogger", "0x1017", "0", "--port", "0"});
  EXPECT_EQ(run.exit, 2);
  EXPECT_NE(run.err.find("ports are numbered as the manuals print them, CAN1 and CAN2"), std::string::npos)
      << run.err;
  handler_.SetAnswer([](const Request&) { return Done("written"); });
  EXPECT_EQ(Canfleet({"sdo", "write", "datalogger", "0x1017", "0", "u16", "1", "--port", "2"}).exit, 0);
  EXPECT_EQ(handler_.Requests().back().sdo_write().port(), 1u);
  EXPECT_EQ(Canfleet({"sdo", "write", "datalogger", "0x1017", "0", "u16", "1", "--port", "CAN1"}).exit, 0);
  EXPECT_EQ(handler_.Requests().back().sdo_write().port(), 0u);
}

// What the orchestrator refuses as a bad request (an unknown node or signal, a value a signal
// refuses, a fault without what its kind needs) is a bad argument too: exit 2, its message (with
// the nearest names) on stderr. A failure of the fleet stays exit 1 (above).
TEST_F(CanfleetCli, ABadRequestTheOrchestratorRefusesExitsWithTwo) {
  handler_.SetAnswer([](const Request&) {
    Response r = Error(
        "no signal IN9.voltage_mV on quad-5; nearest: IN1.voltage_mV, IN2.voltage_mV; all: canfleet io get "
        "quad-5");
    r.set_bad_request(true);
    return r;
  });
  const Outcome run = Canfleet({"io", "set", "quad-5", "IN9.voltage_mV", "1"});
  EXPECT_EQ(run.exit, 2);
  EXPECT_EQ(run.out, "");
  EXPECT_EQ(
      run.err,
      "canfleet: no signal IN9.voltage_mV on quad-5; nearest: IN1.voltage_mV, IN2.voltage_mV; all: canfleet "
      "io get quad-5\n");
}

// A done request with a notice (an old signal name, a quantity the pin's configuration does not
// read): done (exit 0, the usual line on stdout), the notice on stderr.
TEST_F(CanfleetCli, ANoticeGoesToStderrAndTheCommandSucceeds) {
  handler_.SetAnswer([](const Request&) {
    Response r = Done("quad-5 AIN1.voltage_mV = 1800");
    r.set_notice("AIN1.voltage_mV is deprecated: use IN1.voltage_mV");
    return r;
  });
  const Outcome run = Canfleet({"io", "set", "quad-5", "AIN1.voltage_mV", "1800"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "quad-5 AIN1.voltage_mV = 1800\n");
  EXPECT_EQ(run.err, "canfleet: notice: AIN1.voltage_mV is deprecated: use IN1.voltage_mV\n");
}

TEST_F(CanfleetCli, HelpAndVersionExitWithZero) {
  Outcome run = Canfleet({"--help"});
  EXPECT_EQ(run.exit, 0);
  for (const char* command :
       {"up", "down", "check", "status", "fault", "io", "sdo", "nmt", "dump", "capture"})
    EXPECT_NE(run.out.find(std::string("  ") + command), std::string::npos) << command << "\n" << run.out;
  run = Canfleet({"--version"});
  EXPECT_EQ(run.exit, 0);
  EXPECT_EQ(run.out.substr(0, 9), "canfleet ");
}

TEST_F(CanfleetCli, FaultInjectSendsEveryOptionAndPrintsTheSummary) {
  handler_.SetAnswer([](const Request&) {
    Response r;
    r.mutable_fault_injected()->set_fault_id(3);
    r.mutable_fault_injected()->set_summary(
        "drop of frames 0x185 from quad-5 on can0 (to quad-6, quad-7), ...");
    return r;
  });
  const Outcome run =
      Canfleet({"fault",  "inject",     "drop",   "--node",   "quad-5", "--bus",    "can0", "--receiver",
                "quad-6", "--receiver", "quad-7", "--cob-id", "0x185",  "--mask",   "780h", "--probability",
                "0.25",   "--seed",     "42",     "--delay",  "10ms",   "--jitter", "5ms",  "--duration",
                "1.5s",   "--count",    "100",    "--label",  "lossy"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "fault 3: drop of frames 0x185 from quad-5 on can0 (to quad-6, quad-7), ...\n");
  const Request request = OnlyRequest();
  EXPECT_TRUE(Same(request.fault_inject(), Parse<FaultSpec>(R"pb(
                     kind: DROP
                     label: "lossy"
                     node: "quad-5"
                     bus: "can0"
                     receivers: "quad-6"
                     receivers: "quad-7"
                     cob_id: 0x185
                     mask: 0x780
                     probability: 0.25
                     seed: 42
                     delay_ms: 10
                     jitter_ms: 5
                     duration_ms: 1500
                     count: 100)pb")))
      << request.DebugString();
}

TEST_F(CanfleetCli, FaultInjectPartitionGroupsExtendedIdsAndJson) {
  handler_.SetAnswer([](const Request&) {
    Response r;
    r.mutable_fault_injected()->set_fault_id(4);
    r.mutable_fault_injected()->set_summary("partition of can0 into [a, b] and [c], until cleared");
    return r;
  });
  Outcome run =
      Canfleet({"fault", "inject", "partition", "--bus", "can0", "--group", "a,b", "--group", "c", "--json"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(
      run.out,
      "{\n \"fault_id\": 4,\n \"summary\": \"partition of can0 into [a, b] and [c], until cleared\"\n}\n");
  EXPECT_TRUE(Same(OnlyRequest().fault_inject(), Parse<FaultSpec>(R"pb(
                     kind: PARTITION
                     bus: "can0"
                     groups { nodes: "a" nodes: "b" }
                     groups { nodes: "c" })pb")))
      << OnlyRequest().DebugString();

  run = Canfleet({"fault", "inject", "BUS_OFF", "--node", "quad-5", "--manual-recovery"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(Same(handler_.Requests().back().fault_inject(),
                   Parse<FaultSpec>(R"pb(kind: BUS_OFF node: "quad-5" manual_recovery: true)pb")));

  run = Canfleet({"fault", "inject", "heartbeat-loss", "quad-5"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(Same(handler_.Requests().back().fault_inject(), Parse<FaultSpec>(R"pb(kind: HEARTBEAT_LOSS
                                                                                    node: "quad-5")pb")))
      << "the node may also come as a positional";

  run = Canfleet({"fault", "inject", "corrupt", "--cob-id", "0x18FF0001", "--extended"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(Same(handler_.Requests().back().fault_inject(), Parse<FaultSpec>(R"pb(kind: CORRUPT
                                                                                    cob_id: 0x18FF0001
                                                                                    extended: true)pb")));
}

TEST_F(CanfleetCli, FaultClearByIdLabelOrAll) {
  handler_.SetAnswer([](const Request&) { return Done(""); });
  EXPECT_EQ(Canfleet({"fault", "clear", "3"}).out, "cleared\n") << "no detail: a plain confirmation";
  EXPECT_EQ(Canfleet({"fault", "clear", "--label", "hb"}).exit, 0);
  EXPECT_EQ(Canfleet({"fault", "clear", "--all"}).exit, 0);
  const auto requests = handler_.Requests();
  ASSERT_EQ(requests.size(), 3u);
  EXPECT_TRUE(Same(requests[0].fault_clear(), Parse<FaultClear>("fault_id: 3")));
  EXPECT_TRUE(Same(requests[1].fault_clear(), Parse<FaultClear>("label: 'hb'")));
  EXPECT_TRUE(Same(requests[2].fault_clear(), FaultClear()));
  EXPECT_TRUE(requests[2].has_fault_clear());
}

TEST_F(CanfleetCli, FaultListShowsTheEventLogWithAll) {
  handler_.SetAnswer([](const Request& request) {
    Response r;
    if (request.fault_list().include_ended())
      *r.mutable_faults() = Parse<FaultList>(R"pb(
        faults {
          fault_id: 1
          state: "cleared"
          started_s: 10
          ended_s: 20.25
          hits: 5
          summary: "kill of quad-5, until cleared"
        }
        faults {
          fault_id: 2
          state: "active"
          started_s: 30
          summary: "restart of quad-6"
          spec { label: "r" }
        })pb");
    else
      r.mutable_faults();
    return r;
  });
  Outcome run = Canfleet({"fault", "list"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "no active faults\n");
  run = Canfleet({"fault", "list", "--all"});
  EXPECT_EQ(run.out,
            "FAULT  STATE    STARTED  ENDED  HITS  LABEL  SUMMARY\n"
            "    1  cleared    10.0s  20.2s     5  -      kill of quad-5, until cleared\n"
            "    2  active     30.0s      -     0  r      restart of quad-6\n");
  run = Canfleet({"fault", "list", "--all", "--json"});
  FaultList parsed;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(run.out, &parsed).ok()) << run.out;
  EXPECT_EQ(parsed.faults_size(), 2);
  const auto requests = handler_.Requests();
  EXPECT_FALSE(requests[0].fault_list().include_ended());
  EXPECT_TRUE(requests[1].fault_list().include_ended());
}

TEST_F(CanfleetCli, IoSetAndGet) {
  handler_.SetAnswer([](const Request& request) {
    if (request.has_io_set()) return Done("");
    Response r;
    *r.mutable_io() = Parse<IoValues>(R"pb(
      node: "quad-5"
      values { name: "IN1.voltage_mV" value: "2500" unit: "mV" input: true }
      values { name: "OUT1.current_mA" value: "0" unit: "mA" })pb");
    if (!request.io_get().name().empty()) r.mutable_io()->mutable_values()->DeleteSubrange(1, 1);
    return r;
  });
  Outcome run = Canfleet({"io", "set", "quad-5", "IN1.voltage_mV", "2500"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "quad-5 IN1.voltage_mV = 2500\n");
  EXPECT_TRUE(Same(handler_.Requests().back().io_set(),
                   Parse<IoSet>("node: 'quad-5' name: 'IN1.voltage_mV' value: '2500'")));

  run = Canfleet({"io", "get", "quad-5"});
  EXPECT_EQ(run.out,
            "SIGNAL           VALUE  UNIT  DIRECTION\n"
            "IN1.voltage_mV    2500  mV    input\n"
            "OUT1.current_mA      0  mA    output\n");
  run = Canfleet({"io", "get", "quad-5", "IN1.voltage_mV"});
  EXPECT_EQ(run.out, "2500\n") << "one signal: its value alone";
  EXPECT_TRUE(
      Same(handler_.Requests().back().io_get(), Parse<IoGet>("node: 'quad-5' name: 'IN1.voltage_mV'")));
  run = Canfleet({"io", "get", "quad-5", "--json"});
  IoValues parsed;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(run.out, &parsed).ok()) << run.out;
  EXPECT_EQ(parsed.values(0).name(), "IN1.voltage_mV");
}

TEST_F(CanfleetCli, SdoReadSendsTheAddressAndPrintsTheValue) {
  handler_.SetAnswer([](const Request& request) {
    Response r;
    r.mutable_sdo()->set_data(std::string("\xE8\x03", 2));
    if (!request.sdo_read().type().empty()) r.mutable_sdo()->set_text("1000");
    return r;
  });
  Outcome run = Canfleet({"sdo", "read", "quad-5", "0x1017", "0", "u16"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "1000\n");
  EXPECT_TRUE(Same(handler_.Requests().back().sdo_read(),
                   Parse<SdoRead>("node: 'quad-5' index: 0x1017 subindex: 0 type: 'u16'")));

  run = Canfleet({"sdo", "read", "psu-1", "1018h", "0x04", "--block", "--port", "CAN2"});
  EXPECT_EQ(run.out, "E8 03\n") << "without a type: the bytes in hex";
  EXPECT_TRUE(Same(handler_.Requests().back().sdo_read(),
                   Parse<SdoRead>("node: 'psu-1' index: 0x1018 subindex: 4 block: true port: 1")));

  run = Canfleet({"sdo", "read", "quad-5", "0x1017", "0", "u16", "--json"});
  EXPECT_EQ(run.out, "{\n \"data\": \"6AM=\",\n \"text\": \"1000\"\n}\n");
}

TEST_F(CanfleetCli, SdoWriteSendsTheValueAsText) {
  handler_.SetAnswer([](const Request&) { return Done(""); });
  Outcome run = Canfleet({"sdo", "write", "quad-5", "0x2000", "1", "i16", "-5"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "ok\n");
  EXPECT_TRUE(Same(handler_.Requests().back().sdo_write(),
                   Parse<SdoWrite>("node: 'quad-5' index: 0x2000 subindex: 1 type: 'i16' value: '-5'")));
  run = Canfleet({"sdo", "write", "quad-5", "0x1008", "0", "vs", "hello world", "--block"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(
      Same(handler_.Requests().back().sdo_write(),
           Parse<SdoWrite>("node: 'quad-5' index: 0x1008 type: 'vs' value: 'hello world' block: true")));
}

TEST_F(CanfleetCli, SdoAbortsComeBackAsErrors) {
  handler_.SetAnswer([](const Request&) { return Error("SDO abort 06020000: object does not exist"); });
  const Outcome run = Canfleet({"sdo", "read", "quad-5", "0x6000", "0"});
  EXPECT_EQ(run.exit, 1);
  EXPECT_EQ(run.err, "canfleet: SDO abort 06020000: object does not exist\n");
}

TEST_F(CanfleetCli, NmtVerbsMapToActions) {
  handler_.SetAnswer([](const Request&) { return Done(""); });
  const std::pair<const char*, NmtAction> kVerbs[] = {{"start", NMT_START},
                                                      {"stop", NMT_STOP},
                                                      {"preop", NMT_PREOP},
                                                      {"reset", NMT_RESET},
                                                      {"reset-comm", NMT_RESET_COMM}};
  for (const auto& [verb, action] : kVerbs) {
    const Outcome run = Canfleet({"nmt", verb, "quad-5"});
    EXPECT_EQ(run.exit, 0) << run.err;
    EXPECT_EQ(run.out, std::string("NMT ") + verb + " sent to quad-5\n");
    EXPECT_EQ(handler_.Requests().back().nmt().action(), action) << verb;
    EXPECT_EQ(handler_.Requests().back().nmt().node(), "quad-5");
  }
  const Outcome all = Canfleet({"nmt", "start"});
  EXPECT_EQ(all.out, "NMT start sent to every node\n");
  EXPECT_EQ(handler_.Requests().back().nmt().node(), "") << "no node: every node (node-ID 0)";
}

/// Streams a batch of two frames every millisecond until the client goes.
void StreamFrames(const Request& request, std::shared_ptr<Responder> responder, asio::io_context& io,
                  std::shared_ptr<std::atomic<bool>> closed) {
  responder->OnClose([closed] { *closed = true; });
  auto timer = std::make_shared<asio::steady_timer>(io);
  auto n = std::make_shared<std::uint32_t>(0);
  auto tick = std::make_shared<std::function<void()>>();
  // The pending wait owns the loop; the loop refers to itself weakly (no cycle).
  std::weak_ptr<std::function<void()>> weak = tick;
  *tick = [=, id = request.id()] {
    if (responder->Closed()) return;
    Response r;
    r.set_id(id);
    for (int i = 0; i < 2; ++i) {
      auto* f = r.mutable_frames()->add_frames();
      f->set_bus("can0");
      f->set_time_ns(1'700'000'000'123'456'000 + std::int64_t{*n} * 1'000'000);
      f->set_id(0x185);
      f->set_data(std::string{1, 2, 3, static_cast<char>(*n)});
      ++*n;
    }
    responder->Send(r);
    timer->expires_after(1ms);
    timer->async_wait([self = weak.lock()](const asio::error_code& ec) {
      if (!ec) (*self)();
    });
  };
  (*tick)();
}

TEST_F(CanfleetCli, DumpPrintsCandumpLinesAndStopsAfterCount) {
  auto closed = std::make_shared<std::atomic<bool>>(false);
  OnIo([&] {
    handler_.stream_ = [this, closed](const Request& request, std::shared_ptr<Responder> responder) {
      StreamFrames(request, responder, io_, closed);
    };
  });
  const Outcome run = Canfleet(
      {"dump", "--bus", "can0", "--id", "0x185", "--mask", "0x7FF", "--error-frames", "--count", "3"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out,
            "(1700000000.123456) can0 185#01020300\n"
            "(1700000000.124456) can0 185#01020301\n"
            "(1700000000.125456) can0 185#01020302\n");
  EXPECT_TRUE(Same(OnlyRequest().dump(),
                   Parse<DumpRequest>("bus: 'can0' cob_id: 0x185 mask: 0x7FF error_frames: true")));
  EXPECT_TRUE(WaitUntil([&] { return closed->load(); })) << "the stream ends with the connection";
}

TEST_F(CanfleetCli, DumpJsonPrintsOneFramePerLine) {
  auto closed = std::make_shared<std::atomic<bool>>(false);
  OnIo([&] {
    handler_.stream_ = [this, closed](const Request& request, std::shared_ptr<Responder> responder) {
      StreamFrames(request, responder, io_, closed);
    };
  });
  const Outcome run = Canfleet({"dump", "--count", "2", "--json"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(
      run.out,
      "{\"bus\":\"can0\",\"time_ns\":1700000000123456000,\"id\":389,\"extended\":false,\"remote\":false,"
      "\"error\":false,\"data\":\"AQIDAA==\"}\n"
      "{\"bus\":\"can0\",\"time_ns\":1700000000124456000,\"id\":389,\"extended\":false,\"remote\":false,"
      "\"error\":false,\"data\":\"AQIDAQ==\"}\n");
}

TEST_F(CanfleetCli, DumpRunsUntilCtrlCThenExitsWithZero) {
  auto closed = std::make_shared<std::atomic<bool>>(false);
  OnIo([&] {
    handler_.stream_ = [this, closed](const Request& request, std::shared_ptr<Responder> responder) {
      StreamFrames(request, responder, io_, closed);
    };
  });
  ChildProcess child(Argv({"dump"}), dir_.File("dump.stderr"));
  ASSERT_TRUE(child.WaitForPrefix("(1700000000.").has_value()) << child.Log();
  ASSERT_TRUE(
      child.WaitForLine([](const std::string& l) { return l.ends_with("185#01020305"); }).has_value());
  child.Signal(SIGINT);
  const Outcome run = Finish(child);
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_TRUE(WaitUntil([&] { return closed->load(); }));
}

TEST_F(CanfleetCli, DumpShowsRemoteAndExtendedFramesAsCandumpDoes) {
  OnIo([&] {
    handler_.stream_ = [](const Request& request, std::shared_ptr<Responder> responder) {
      Response r;
      r.set_id(request.id());
      *r.mutable_frames() = Parse<FrameBatch>(R"pb(
        frames { bus: "can1" time_ns: 5000000 id: 0x705 remote: true data: "\0" }
        frames { bus: "can1" time_ns: 6000000 id: 0x1ABCDEF0 extended: true data: "\x11\x22" }
        frames { bus: "can1" time_ns: 7000000 id: 0x080 })pb");
      responder->Send(r);
    };
  });
  const Outcome run = Canfleet({"dump", "can1", "--count", "3"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(OnlyRequest().dump().bus(), "can1") << "the bus may also come as a positional";
  EXPECT_EQ(run.out,
            "(0000000000.005000) can1 705#R1\n"
            "(0000000000.006000) can1 1ABCDEF0#1122\n"
            "(0000000000.007000) can1 080#\n");
}

TEST_F(CanfleetCli, ADumpTheOrchestratorRefusesExitsWithOne) {
  handler_.SetAnswer([](const Request&) { return Error("no bus called 'can7'"); });
  const Outcome run = Canfleet({"dump", "--bus", "can7"});
  EXPECT_EQ(run.exit, 1);
  EXPECT_EQ(run.err, "canfleet: no bus called 'can7'\n");
}

TEST_F(CanfleetCli, CaptureStartSendsThePathAsGivenAndStopTheId) {
  handler_.SetAnswer([](const Request& request) {
    if (request.has_capture_stop()) return Done("capture 1: 120 frames of can0 in /tmp/x.pcap");
    Response r;
    r.mutable_capture()->set_capture_id(1);
    r.mutable_capture()->set_path(request.capture_start().path());
    return r;
  });
  // A relative file goes to the fleet's capture folder: the orchestrator resolves it, not the CLI.
  Outcome run = Canfleet({"capture", "start", "--bus", "can0", "--file", "trace.log", "--format", "candump"});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out, "capture 1: can0 -> trace.log\n");
  EXPECT_TRUE(Same(handler_.Requests().back().capture_start(),
                   Parse<CaptureStart>("bus: 'can0' path: 'trace.log' format: 'candump'")));

  run = Canfleet({"capture", "start", "--bus", "can0", "--file", "/tmp/x.pcap", "--json"});
  EXPECT_EQ(run.out, "{\n \"capture_id\": 1,\n \"path\": \"/tmp/x.pcap\"\n}\n");
  EXPECT_EQ(handler_.Requests().back().capture_start().format(), "pcap") << "the default format";

  run = Canfleet({"capture", "stop", "1"});
  EXPECT_EQ(run.out, "capture 1: 120 frames of can0 in /tmp/x.pcap\n");
  EXPECT_EQ(handler_.Requests().back().capture_stop().capture_id(), 1u);
  Canfleet({"capture", "stop"});
  EXPECT_EQ(handler_.Requests().back().capture_stop().capture_id(), 0u) << "no id: every capture";
}

TEST_F(CanfleetCli, CheckLoadsATopologyWithoutAnOrchestrator) {
  const std::string good = dir_.File("good.textproto");
  std::ofstream(good) << "name: \"t\"\n"
                         "bus { name: \"can0\" }\n"
                         "node { name: \"quad-5\" device: \"quad-controller\" node_id: 5 bus: \"can0\" }\n"
                         "node { name: \"quad-6\" device: \"quad-controller\" node_id: 6 bus: \"can0\" }\n";
  Outcome run = Canfleet({"check", good});
  EXPECT_EQ(run.exit, 0) << run.err;
  // Two Quads' four TPDOs every 100 ms (AX020506 §3.1.1), 440 bits at most, on 500 kbit/s.
  EXPECT_EQ(run.out, "ok: 1 bus, 2 nodes; offered load can0 1.8 % of 500 kbit/s (TPDOs 1.8 %)\n");
  EXPECT_EQ(run.err, "");

  const std::string bad = dir_.File("bad.textproto");
  std::ofstream(bad) << "name: \"t\"\n"
                        "bus { name: \"can0\" }\n"
                        "node { name: \"quad-5\" device: \"quad-controller\" node_id: 5 bus: \"can9\" }\n";
  run = Canfleet({"check", bad});
  EXPECT_EQ(run.exit, 2);
  EXPECT_EQ(run.err.substr(0, bad.size() + 3), bad + ":3:") << run.err;
  EXPECT_NE(run.err.find("can9"), std::string::npos) << run.err;
  EXPECT_TRUE(handler_.Requests().empty());
}

// A topology that loads but cannot work: one line per warning on stderr, located like an error,
// the load per bus and the count on the summary line, exit 0 (topologies/README.md "What loading
// warns about").
TEST_F(CanfleetCli, CheckWarnsAboutWhatCannotWorkAndStillSucceeds) {
  const std::string file = dir_.File("warn.textproto");
  std::ofstream out(file);
  out << "name: \"t\"\n"
         "bus { name: \"can0\" bitrate: 125000 }\n"
         "node { name: \"quad-6\" device: \"quad-controller\" node_id: 6 bus: \"can0\"\n"
         "  heartbeat { consumer { node: \"quad-1\" timeout_ms: 1000 } } }\n";
  // 40 operational Quads at 125 kbit/s: 40 × 4400 bit/s of TPDOs = 141 %.
  for (int id = 1; id <= 40; ++id) {
    if (id == 6) continue;
    out << "node { name: \"quad-" << id << "\" device: \"quad-controller\" node_id: " << id
        << " bus: \"can0\" }\n";
  }
  out.close();
  const Outcome run = Canfleet({"check", file});
  EXPECT_EQ(run.exit, 0) << run.err;
  EXPECT_EQ(run.out,
            "ok: 1 bus, 40 nodes; offered load can0 141 % of 125 kbit/s (TPDOs 141 %); 2 warnings\n");
  EXPECT_EQ(
      run.err.substr(0, run.err.find('\n') + 1),
      file +
          ":4:15: warning: node[0].heartbeat.consumer[0]: quad-6 consumes the heartbeat of quad-1 (node-ID 1 "
          "on can0), which sends none: its 1017h is 0 (its default; set its heartbeat.producer_ms). "
          "Monitoring "
          "starts with the first heartbeat (CiA 301 §7.2.8.3.2.2), so no loss is ever reported\n");
  EXPECT_NE(run.err.find(
                file + ":2:20: warning: bus[0].bitrate: bus can0: periodic traffic offers 141 % of "
                       "125 kbit/s (TPDOs 141 %): configuration SDOs and low-priority frames will starve\n"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 2);
  EXPECT_TRUE(handler_.Requests().empty());
}

}  // namespace
}  // namespace canfleet::control

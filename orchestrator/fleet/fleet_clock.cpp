// A test driving the fleet's virtual time in steps (ClockAdvance), and expectations asked through
// the control API (ExpectRequest), judged by the scenario's runner: python/README.md "Virtual time".
#include <google/protobuf/text_format.h>
#include <spdlog/spdlog.h>

#include <asio/post.hpp>

#include "orchestrator/fleet/control_replies.hpp"
#include "orchestrator/fleet/fleet.hpp"
#include "orchestrator/scenario/judge.hpp"

namespace canfleet::fleet {

namespace {

std::int64_t Ns(TimePoint t) {
  return t.time_since_epoch().count();
}

}  // namespace

void Fleet::AdvanceClock(const control::Request& request, std::shared_ptr<control::Responder> responder) {
  transport::TimeConductor* conductor = options_.conductor;
  if (conductor == nullptr || !conductor->Driven()) {
    responder->Send(Failed(request,
                           conductor == nullptr
                               ? "this fleet runs in real time: there is no clock to advance"
                               : "this fleet's virtual time runs on its own (started without "
                                 "--driven, or not ready yet): nothing to advance",
                           true));
    return;
  }
  if (conductor->Advancing()) {
    responder->Send(Failed(request, "the clock is already advancing (one driver at a time)"));
    return;
  }
  const auto reply = [request, responder, conductor](bool woken) {
    control::Response response = Reply(request);
    response.mutable_clock()->set_now_ns(Ns(conductor->Now()));
    response.mutable_clock()->set_woken(woken);
    responder->Send(response);
  };
  // An answer this client has not read yet: it acts on it first, at the time it came.
  if (responder->Sent() > request.clock_advance().responses_seen()) return reply(true);
  // Any later answer on this connection reaches the driver: the step ends where it happened.
  responder->OnSent([conductor] { conductor->Wake(); });
  conductor->Advance(TimePoint(Duration(request.clock_advance().until_ns())), reply);
}

void Fleet::StartExpect(const control::Request& request, std::shared_ptr<control::Responder> responder) {
  namespace pb = google::protobuf;
  topology::Expect expect;
  pb::TextFormat::Parser parser;
  if (!parser.ParseFromString(request.expect().expect(), &expect))
    return responder->Send(
        Failed(request, "expect: not an Expect in text format: " + request.expect().expect(), true));
  if (!expect.after().empty())
    return responder->Send(Failed(request,
                                  "expect: `after` names a scenario step; an asked expectation "
                                  "opens when it is asked",
                                  true));
  // The fleet's topology with this one step as its scenario, loaded as a file is: names, ports and
  // values are checked, `can:` numbered, defaults applied, exactly as in a scenario.
  topology::Topology spec = options_.topology;
  spec.clear_scenario();
  spec.set_scenario_repeat_ms(0);
  *spec.add_scenario()->mutable_expect() = expect;
  std::string text;
  pb::TextFormat::PrintToString(spec, &text);
  auto asked = std::make_unique<AskedExpectation>();
  try {
    asked->topology = topology::ParseTopology(text, ScenarioSource());
  } catch (const topology::TopologyError& e) {
    // The location is in the text made here, not the user's: keep what it says.
    std::string what = e.what();
    if (const auto at = what.find(": scenario"); at != std::string::npos) what = what.substr(at + 2);
    return responder->Send(Failed(request, "expect: " + what, true));
  }
  const std::uint64_t id = next_asked_++;
  AskedExpectation& a = *asked;
  a.runner = std::make_unique<scenario::ScenarioRunner>(
      scheduler_, a.topology.spec, *this,
      scenario::ScenarioRunner::Hooks{
          .act = nullptr,
          .decided =
              [this, request, responder, id](const scenario::Result& result) {
                control::Response response = Reply(request);
                control::ExpectResult* r = response.mutable_expect();
                r->set_outcome(scenario::OutcomeName(result.verdict.outcome));
                r->set_description(result.description);
                r->set_detail(result.verdict.detail);
                if (result.opened) r->set_opened_ns(Ns(*result.opened));
                r->set_decided_ns(Ns(result.verdict.time));
                responder->Send(response);
                // Not from inside the runner's own hook: it goes at the end of this turn.
                asio::post(io_, [this, id] { asked_.erase(id); });
              },
          .began = nullptr,
          .done = nullptr,
      });
  for (const auto& bus : broker_.Buses())
    a.taps.push_back(std::make_unique<ScenarioTap>(broker_, bus, *a.runner));
  responder->OnClose([this, id] { asio::post(io_, [this, id] { asked_.erase(id); }); });
  asked_.emplace(id, std::move(asked));
  a.runner->Start();
}

}  // namespace canfleet::fleet

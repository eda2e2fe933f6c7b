#include "orchestrator/topology/scenario_checks.hpp"

#include <algorithm>
#include <set>
#include <vector>

#include "orchestrator/control/fault_kinds.hpp"
#include "orchestrator/topology/expect_checks.hpp"
#include "orchestrator/topology/node_checks.hpp"
#include "orchestrator/topology/port_numbering.hpp"

namespace canfleet::topology::detail {

void ScenarioChecks::CheckScenario(const Scope& root) {
  // Steps run by time, those at the same time in file order: "earlier" for labels means that.
  std::vector<int> order(static_cast<std::size_t>(facts_.spec.scenario_size()));
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = static_cast<int>(i);
  std::stable_sort(order.begin(), order.end(), [this](int a, int b) {
    return facts_.spec.scenario(a).at_ms() < facts_.spec.scenario(b).at_ms();
  });
  // Names, and what expectations are timed after: a named step earlier in the file.
  std::map<std::string, int> names;
  for (int i = 0; i < facts_.spec.scenario_size(); ++i) {
    const Step& step = facts_.spec.scenario(i);
    const Scope s = root.Child("scenario", step, i);
    if (step.has_expect() && !step.expect().after().empty() && !names.contains(step.expect().after()))
      s.Child("expect", step.expect())
          .Fail("after", "no step earlier in the file is named " + Quote(step.expect().after()));
    if (step.name().empty()) continue;
    if (const std::string problem = BusNameProblem(step.name()); !problem.empty())
      s.Fail("name", "step name " + problem);
    const auto [it, fresh] = names.emplace(step.name(), i);
    if (!fresh)
      s.Fail("name", Quote(step.name()) + " already names scenario[" + std::to_string(it->second) + "] (" +
                         LineRef(root.Child("scenario", facts_.spec.scenario(it->second), it->second).loc()) +
                         ")");
  }
  std::map<std::string, int> labels;  // label -> step that injects it
  std::set<std::string> cleared;      // labels a later step clears
  for (int i : order) {
    const Step& step = facts_.spec.scenario(i);
    const Scope s = root.Child("scenario", step, i);
    switch (step.action_case()) {
      case Step::kInject:
        CheckInject(s.Child("inject", step.inject()), step.inject(), i, labels);
        break;
      case Step::kClear:
        CheckClear(s.Child("clear", step.clear()), step.clear(), labels);
        if (step.clear().label().empty())  // clears every fault active so far
          for (const auto& [label, at] : labels)
            cleared.insert(label);
        else
          cleared.insert(step.clear().label());
        break;
      case Step::kIo: {
        const Scope is = s.Child("io", step.io());
        const NodeFacts& facts = facts_.RequireNode(is, "node", step.io().node());
        CheckIoSet(is, "name", "value", facts, step.io().name(), step.io().value());
        break;
      }
      case Step::kNmt: {
        const Scope ns = s.Child("nmt", step.nmt());
        const control::NmtAction action = step.nmt().action();
        if (action == control::NMT_ACTION_UNSPECIFIED || !control::NmtAction_IsValid(action))
          ns.Fail("action", "required: NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET or NMT_RESET_COMM");
        if (!step.nmt().node().empty()) facts_.RequireNode(ns, "node", step.nmt().node());
        break;
      }
      case Step::kSdo: {
        const control::SdoWrite& w = step.sdo();
        const Scope ws = s.Child("sdo", w);
        const NodeFacts& facts = facts_.RequireNode(ws, "node", w.node());
        CheckSdo(ws, facts, w.index(), w.subindex(), w.type(), w.value(), w.port(), PortFieldName(w));
        break;
      }
      case Step::kExpect:
        CheckExpect(s.Child("expect", step.expect()), facts_, step.expect());
        break;
      case Step::ACTION_NOT_SET:
        s.FailHere("a step needs an action: inject, clear, io, nmt, sdo or expect");
    }
  }
  CheckRepeat(root, labels, cleared);
}

void ScenarioChecks::CheckRepeat(const Scope& root, const std::map<std::string, int>& labels,
                                 const std::set<std::string>& cleared) const {
  if (facts_.spec.scenario_repeat_ms() == 0) return;
  if (facts_.spec.scenario().empty()) root.Fail("scenario_repeat_ms", "there is no scenario to repeat");
  // The next run injects the same labels again: one still active from the last run is refused
  // by the fleet ("already active"), so the run that repeats must leave none behind.
  for (const auto& [label, step] : labels) {
    const control::FaultSpec& f = facts_.spec.scenario(step).inject();
    if (cleared.contains(label) || control::IsOneShot(f)) continue;
    root.Child("scenario", facts_.spec.scenario(step), step)
        .Child("inject", f)
        .Fail("label", "the scenario repeats (scenario_repeat_ms) but never clears " + Quote(label) +
                           ": its next run could not inject it again");
  }
}

void ScenarioChecks::CheckInject(const Scope& s, const control::FaultSpec& f, int step,
                                 std::map<std::string, int>& labels) {
  auto check = [&s](const control::FaultSpec& spec) {
    if (const auto problem = control::CheckFaultSpec(spec, control::FaultSpelling::kTopology))
      s.Fail(problem->field, problem->index, problem->reason);
  };
  const control::FaultKindTraits* kind = control::TraitsOf(f.kind());
  if (kind == nullptr) check(f);  // says a kind is required, and which
  if (!f.label().empty()) {
    const auto [it, fresh] = labels.emplace(f.label(), step);
    if (!fresh)
      s.Fail("label", "label " + Quote(f.label()) + " is already used by scenario[" +
                          std::to_string(it->second) + "]");
  }
  const NodeFacts* node = f.node().empty() ? nullptr : &facts_.RequireNode(s, "node", f.node());
  if (!f.bus().empty() && !facts_.buses.contains(f.bus()))
    s.Fail("bus", "unknown bus " + Quote(f.bus()) + " (the topology's buses: " + facts_.BusNames() + ")");
  if (node != nullptr && !f.bus().empty()) facts_.CheckOnBus(s, "node", -1, *node, f.bus());
  // The bus defaults to the node's first (ApplyDefaults), before the kind's needs are checked.
  control::FaultSpec defaulted = f;
  if (defaulted.bus().empty() && node != nullptr && kind->takes.Has(control::FaultOption::kBus))
    defaulted.set_bus(node->buses.front());
  check(defaulted);
  const std::string& bus = defaulted.bus();

  if (kind->target == control::FaultTarget::kProcess && facts_.spec.node(node->index).external())
    s.Fail("node", "node " + node->name + " is external (started elsewhere): " +
                       control::FaultKind_Name(f.kind()) + " cannot reach its process");
  for (int r = 0; r < f.receivers_size(); ++r) {
    const NodeFacts& receiver = facts_.RequireNode(s, "receivers", f.receivers(r));
    if (!bus.empty()) facts_.CheckOnBus(s, "receivers", r, receiver, bus);
  }
  std::map<std::string, int> grouped;
  for (int g = 0; g < f.groups_size(); ++g) {
    const Scope gs = s.Child("groups", f.groups(g), g);
    if (f.groups(g).nodes_size() == 0) gs.FailHere("a group needs at least one node");
    for (int n = 0; n < f.groups(g).nodes_size(); ++n) {
      const std::string& name = f.groups(g).nodes(n);
      const NodeFacts& member = facts_.RequireNode(gs, "nodes", name);
      facts_.CheckOnBus(gs, "nodes", n, member, bus);
      const auto [it, fresh] = grouped.emplace(name, g);
      if (!fresh)
        gs.Fail("nodes", n, "node " + name + " is already in groups[" + std::to_string(it->second) + "]");
    }
  }
}

void ScenarioChecks::CheckClear(const Scope& s, const control::FaultClear& c,
                                const std::map<std::string, int>& labels) {
  if (c.fault_id() != 0)
    s.Fail("fault_id", "fault ids are given out at run time: a scenario clears by label");
  if (!c.label().empty() && !labels.contains(c.label()))
    s.Fail("label", "no earlier step injects a fault labelled " + Quote(c.label()) +
                        " (steps run by at_ms, then in file order)");
}

}  // namespace canfleet::topology::detail

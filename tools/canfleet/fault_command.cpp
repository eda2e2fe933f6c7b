// canfleet fault inject KIND ..., fault clear [ID] [--label L] [--all], fault list [--all] [--json]
#include <algorithm>
#include <iostream>
#include <memory>
#include <sstream>
#include <string_view>
#include <vector>

#include "orchestrator/control/fault_kinds.hpp"
#include "orchestrator/control/fault_text.hpp"
#include "tools/canfleet/cli.hpp"
#include "tools/canfleet/text_format.hpp"
#include "vocabulary/nearest_names.hpp"

namespace canfleet::cli {

namespace {

struct InjectArgs {
  std::string kind;
  std::string node;
  std::string bus;
  std::vector<std::string> receivers;
  std::string cob_id;
  std::string mask;
  bool extended = false;
  double probability = 0;
  std::uint64_t seed = 0;
  std::string delay;
  std::string jitter;
  std::string duration;
  std::uint64_t count = 0;
  std::vector<std::string> groups;
  bool manual_recovery = false;
  std::string label;
  bool json = false;
};

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream s(text);
  for (std::string item; std::getline(s, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

control::FaultSpec BuildSpec(const InjectArgs& a) {
  control::FaultSpec spec;
  spec.set_kind(*control::ParseFaultKind(a.kind));  // validated by the parser
  spec.set_label(a.label);
  spec.set_node(a.node);
  spec.set_bus(a.bus);
  for (const auto& r : a.receivers)
    spec.add_receivers(r);
  const std::uint32_t max_id = a.extended ? 0x1FFFFFFF : 0x7FF;
  if (!a.cob_id.empty()) spec.set_cob_id(ParseHex(a.cob_id, "--cob-id", max_id));
  if (!a.mask.empty()) spec.set_mask(ParseHex(a.mask, "--mask", max_id));
  spec.set_extended(a.extended);
  spec.set_probability(a.probability);
  spec.set_seed(a.seed);
  if (!a.delay.empty()) spec.set_delay_ms(DurationMs(a.delay));
  if (!a.jitter.empty()) spec.set_jitter_ms(DurationMs(a.jitter));
  if (!a.duration.empty()) spec.set_duration_ms(DurationMs(a.duration));
  spec.set_count(a.count);
  for (const auto& g : a.groups) {
    auto* group = spec.add_groups();
    for (const auto& n : SplitCommas(g))
      group->add_nodes(n);
  }
  spec.set_manual_recovery(a.manual_recovery);
  return spec;
}

int RunInject(const GlobalOptions& global, const InjectArgs& args) {
  control::Request request;
  *request.mutable_fault_inject() = BuildSpec(args);
  const control::Response response = Call(global, request);
  if (args.json)
    PrintJson(response.fault_injected());
  else
    std::cout << FormatFaultInjected(response.fault_injected());
  return kExitOk;
}

CLI::Validator FaultKindValidator() {
  std::string names;
  for (const auto& n : control::FaultKindNames())
    names += (names.empty() ? "" : ", ") + n;
  return CLI::Validator(
      [names](std::string& s) {
        if (control::ParseFaultKind(s)) return std::string();
        std::vector<std::string> kinds;
        for (const auto& n : control::FaultKindNames())
          kinds.emplace_back(n);
        const auto nearest = NearestNames(s, kinds);
        return "unknown fault kind \"" + s + "\" (" +
               (nearest.empty() ? "" : "nearest: " + JoinNames(nearest) + "; ") + "kinds: " + names + ")";
      },
      "KIND");
}

/// The footer of `fault inject --help`: what each kind does, from the table of fault kinds
/// (orchestrator/control/fault_kinds.hpp), which also says what each kind takes: the orchestrator
/// refuses an option that does not apply.
std::string KindsHelp() {
  std::string out = "Kinds:";
  for (const control::FaultKindTraits& k : control::FaultKinds()) {
    std::string name(k.name);
    name.resize(std::max<std::size_t>(name.size() + 2, 16), ' ');
    out += "\n  " + name + std::string(k.help);
  }
  return out;
}

std::string Join(const std::vector<std::string_view>& names) {
  std::string out;
  for (const std::string_view name : names)
    out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

/// "heartbeat-loss, drop, delay: " + what, or "all kinds but restart, power-cycle: " + what: an
/// option's help, naming the kinds that take it.
std::string For(control::FaultOption option, const std::string& what) {
  std::vector<std::string_view> takes, refuses;
  for (const control::FaultKindTraits& k : control::FaultKinds())
    (k.takes.Has(option) ? takes : refuses).push_back(k.name);
  return (refuses.size() < takes.size() ? "all kinds but " + Join(refuses) : Join(takes)) + ": " + what;
}

void AddInject(CLI::App& fault, Cli& cli) {
  auto a = std::make_shared<InjectArgs>();
  CLI::App* inject = fault.add_subcommand("inject", "Inject a fault; prints its id and what it does");
  inject->add_option("KIND", a->kind, "What kind of fault")->required()->check(FaultKindValidator());
  auto* node = inject->add_option("--node", a->node, "The node concerned (see the kinds below)");
  inject->add_option("NODE", a->node, "The same as --node")->excludes(node);
  inject->add_option("--bus", a->bus, "The bus (default: the node's first bus)");
  using control::FaultOption;
  inject
      ->add_option("--receiver", a->receivers,
                   For(FaultOption::kReceivers, "only this node misses the frames (repeatable; default all)"))
      ->allow_extra_args(false);
  inject
      ->add_option("--cob-id", a->cob_id,
                   For(FaultOption::kCobId, "identifier the fault matches, in hex (0x185 or 185h)"))
      ->check(HexValidator(0x1FFFFFFF));
  inject
      ->add_option("--mask", a->mask,
                   For(FaultOption::kMask, "identifier mask, in hex (default: exact match)"))
      ->check(HexValidator(0x1FFFFFFF));
  inject->add_flag(
      "--extended", a->extended,
      For(FaultOption::kExtended, "--cob-id is a 29-bit identifier (without it: 29-bit frames only)"));
  inject
      ->add_option("--probability", a->probability,
                   For(FaultOption::kProbability, "chance that a matching frame is hit (default 1)"))
      ->check(CLI::Range(0.0, 1.0));
  inject->add_option("--seed", a->seed,
                     For(FaultOption::kSeed, "seed of the random draws (reproducible runs)"));
  inject->add_option("--delay", a->delay, For(FaultOption::kDelay, "fixed delay (10ms)"))
      ->check(DurationValidator());
  inject->add_option("--jitter", a->jitter, For(FaultOption::kJitter, "random extra delay, 0..JITTER (5ms)"))
      ->check(DurationValidator());
  inject
      ->add_option("--duration", a->duration,
                   For(FaultOption::kDuration,
                       "end the fault after this long (5s; default: until cleared); bus-off: held this long"))
      ->check(DurationValidator());
  inject->add_option("--count", a->count, For(FaultOption::kCount, "end after hitting this many frames"));
  inject
      ->add_option("--group", a->groups,
                   For(FaultOption::kGroups, "one group of nodes, comma-separated (repeat per group)"))
      ->allow_extra_args(false);
  inject->add_flag("--manual-recovery", a->manual_recovery,
                   For(FaultOption::kManualRecovery, "stay bus-off until the fault is cleared"));
  inject->add_option("--label", a->label, "A name to clear the fault by");
  inject->add_flag("--json", a->json, "Print the FaultInjected message as JSON");
  inject->footer(KindsHelp());
  inject->callback([&cli, a] { cli.action = [&cli, a] { return RunInject(cli.global, *a); }; });
}

struct ClearArgs {
  std::uint32_t id = 0;
  std::string label;
  bool all = false;
};

void AddClear(CLI::App& fault, Cli& cli) {
  auto a = std::make_shared<ClearArgs>();
  CLI::App* clear = fault.add_subcommand("clear", "End a fault (by id or label) or every fault (--all)");
  auto* id = clear->add_option("ID", a->id, "The fault's id (from fault inject or fault list)");
  auto* label = clear->add_option("--label", a->label, "The fault's label");
  auto* all = clear->add_flag("--all", a->all, "Clear every fault");
  id->excludes(label)->excludes(all);
  label->excludes(all);
  clear->callback([&cli, a, id, label, all] {
    if (id->count() == 0 && label->count() == 0 && all->count() == 0)
      throw CLI::ValidationError("fault clear", "say which fault: an ID, --label LABEL or --all");
    if (id->count() != 0 && a->id == 0) throw CLI::ValidationError("ID", "fault ids start at 1");
    cli.action = [&cli, a] {
      control::Request request;
      auto* body = request.mutable_fault_clear();
      body->set_fault_id(a->id);
      body->set_label(a->label);
      PrintDone(Call(cli.global, request), "cleared");
      return kExitOk;
    };
  });
}

void AddList(CLI::App& fault, Cli& cli) {
  auto all = std::make_shared<bool>(false);
  auto json = std::make_shared<bool>(false);
  CLI::App* list = fault.add_subcommand("list", "Active faults; with --all also those that ended");
  list->add_flag("--all", *all, "Include faults that expired or were cleared");
  list->add_flag("--json", *json, "Print the FaultList message as JSON");
  list->callback([&cli, all, json] {
    cli.action = [&cli, all, json] {
      control::Request request;
      request.mutable_fault_list()->set_include_ended(*all);
      const control::Response response = Call(cli.global, request);
      if (*json)
        PrintJson(response.faults());
      else
        std::cout << FormatFaultList(response.faults(), *all);
      return kExitOk;
    };
  });
}

}  // namespace

void AddFaultCommands(CLI::App& app, Cli& cli) {
  CLI::App* fault = app.add_subcommand("fault", "Inject, clear and list faults");
  fault->require_subcommand(1);
  AddInject(*fault, cli);
  AddClear(*fault, cli);
  AddList(*fault, cli);
}

}  // namespace canfleet::cli

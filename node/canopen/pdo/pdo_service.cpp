#include "node/canopen/pdo/pdo_service.hpp"

namespace canfleet::canopen {

namespace {
constexpr std::uint16_t kSyncWindowLengthIndex = 0x1007;
}  // namespace

PdoService::PdoService(ObjectDictionary& od, BusPort& port, Scheduler& scheduler, CommErrorSink& errors)
    : ctx_{od, port, scheduler, errors, counters_, od.Find(kSyncWindowLengthIndex, 0), std::nullopt, {}} {
  const auto last = static_cast<std::uint16_t>(kRpdoCommBase + kMaxPdos - 1);
  for (auto it = od.objects().lower_bound(kRpdoCommBase); it != od.objects().end() && it->first <= last;
       ++it) {
    if (!it->second.subs.contains(1)) continue;
    auto* mapping = od.Find(static_cast<std::uint16_t>(it->first + kMappingOffset));
    rpdos_.push_back(std::make_unique<Rpdo>(ctx_, it->first - kRpdoCommBase + 1, it->second, mapping));
    InstallHooks(*rpdos_.back());
  }
  const auto tlast = static_cast<std::uint16_t>(kTpdoCommBase + kMaxPdos - 1);
  for (auto it = od.objects().lower_bound(kTpdoCommBase); it != od.objects().end() && it->first <= tlast;
       ++it) {
    if (!it->second.subs.contains(1)) continue;
    auto* mapping = od.Find(static_cast<std::uint16_t>(it->first + kMappingOffset));
    tpdos_.push_back(std::make_unique<Tpdo>(ctx_, it->first - kTpdoCommBase + 1, it->second, mapping));
    InstallHooks(*tpdos_.back());
    tpdo_by_number_.resize(tpdos_.back()->number(), nullptr);
    tpdo_by_number_.back() = tpdos_.back().get();
  }
}

PdoService::~PdoService() = default;

template <typename Pdo>
void PdoService::InstallHooks(Pdo& pdo) {
  auto reconfigure = [&pdo](SubObject&, Origin) { pdo.Reconfigure(); };
  for (auto& [sub_index, sub] : pdo.config().comm_record().subs) {
    if (sub_index == 0) continue;
    sub.AddValidator([&pdo](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
      return pdo.config().CheckCommWrite(s.sub_index, data);
    });
    sub.AddListener(reconfigure);
  }
  if (Object* mapping = pdo.config().mapping_record()) {
    for (auto& [sub_index, sub] : mapping->subs) {
      sub.AddValidator([&pdo](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
        return pdo.config().CheckMappingWrite(s.sub_index, data);
      });
      sub.AddListener(reconfigure);
    }
  }
}

void PdoService::SetNodeId(std::uint8_t /*node_id*/) {
  for (auto& rpdo : rpdos_)
    rpdo->Reconfigure();
  for (auto& tpdo : tpdos_)
    tpdo->Reconfigure();
}

void PdoService::SetNmtState(NmtState state) {
  const bool operational = PdoAllowed(state);
  if (operational == operational_) return;
  operational_ = operational;
  for (auto& rpdo : rpdos_)
    rpdo->SetOperational(operational);
  for (auto& tpdo : tpdos_)
    tpdo->SetOperational(operational);
}

void PdoService::AddListenedIds(std::vector<std::uint32_t>& ids) const {
  for (const auto& rpdo : rpdos_)
    if (rpdo->Listening() && !rpdo->config().comm().cob_id.extended)
      ids.push_back(rpdo->config().comm().cob_id.can_id);
  for (const auto& tpdo : tpdos_)
    if (tpdo->Listening() && !tpdo->config().comm().cob_id.extended)
      ids.push_back(tpdo->config().comm().cob_id.can_id);
}

bool PdoService::OnFrame(const CanFrame& frame) {
  if (!operational_ || frame.error()) return false;
  if (frame.remote()) {
    for (auto& tpdo : tpdos_) {
      if (tpdo->OnRemoteRequest(frame)) return true;
    }
    return false;
  }
  for (auto& rpdo : rpdos_) {
    if (rpdo->OnFrame(frame)) return true;
  }
  return false;
}

// CiA 301 §7.2.2: at a SYNC, synchronous RPDOs received since the previous one are actuated
// and synchronous TPDOs sample and send; actuating first lets a TPDO report what was just written.
void PdoService::OnSync(std::uint8_t counter) {
  ctx_.last_sync = ctx_.scheduler.Now();
  if (!operational_) return;
  for (auto& rpdo : rpdos_)
    rpdo->OnSync();
  for (auto& tpdo : tpdos_)
    tpdo->OnSync(counter);
}

void PdoService::NotifyChanged(const SubObject& sub) {
  for (auto& tpdo : tpdos_) {
    if (tpdo->Maps(sub)) tpdo->OnEvent();
  }
}

void PdoService::RequestTpdo(std::size_t tpdo_number) {
  if (tpdo_number == 0 || tpdo_number > tpdo_by_number_.size()) return;
  if (Tpdo* tpdo = tpdo_by_number_[tpdo_number - 1]) tpdo->OnEvent();
}

}  // namespace canfleet::canopen

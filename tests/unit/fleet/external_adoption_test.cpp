// Adopting external nodes that kept running while the orchestrator restarted
// (orchestrator/fleet/external_adoption): they attach without a boot-up, and NMT reset
// communication (CiA 301 §7.2.8.3.1.5, command 82h) makes them send one.
#include "orchestrator/fleet/external_adoption.hpp"

#include <gtest/gtest.h>

#include <set>

namespace canfleet::fleet {
namespace {

using namespace std::chrono_literals;

class ExternalAdoptionTest : public ::testing::Test {
 protected:
  ExternalAdoptionTest()
      : adoption_(
            ExternalAdoption::Context{
                .scheduler = scheduler_,
                .attached = [this](const std::string&,
                                   const std::string& name) { return attached_.count(name) != 0; },
                .booted = [this](const std::string&, std::uint8_t id) { return booted_.count(id) != 0; },
                .reset_communication =
                    [this](const ExternalAdoption::Port& port) { resets_.push_back(port.name); },
            },
            {{"remote-8", "can0", 8}, {"remote-9", "can1", 9}}) {
    adoption_.Start();
  }

  SimulatedScheduler scheduler_;
  std::set<std::string> attached_;
  std::set<std::uint8_t> booted_;
  std::vector<std::string> resets_;
  ExternalAdoption adoption_;
};

TEST_F(ExternalAdoptionTest, ANodeThatBootsWhenItAttachesIsLeftAlone) {
  attached_.insert("remote-8");
  scheduler_.Advance(300ms);
  booted_.insert(8);
  scheduler_.Advance(30s);
  EXPECT_TRUE(resets_.empty());
}

TEST_F(ExternalAdoptionTest, ARunningNodeAttachingWithoutABootUpIsResetAfterTheGraceTime) {
  attached_.insert("remote-8");
  scheduler_.Advance(ExternalAdoption::kGrace);  // the first check that sees it starts the grace time
  EXPECT_TRUE(resets_.empty());
  scheduler_.Advance(2 * ExternalAdoption::kCheckPeriod);
  EXPECT_EQ(resets_, std::vector<std::string>{"remote-8"});
  // It booted: no more resets.
  booted_.insert(8);
  scheduler_.Advance(30s);
  EXPECT_EQ(resets_.size(), 1u);
}

TEST_F(ExternalAdoptionTest, AnUnansweredResetIsRepeatedAfterTheRetryTimeNotSooner) {
  attached_.insert("remote-9");
  scheduler_.Advance(ExternalAdoption::kGrace + 2 * ExternalAdoption::kCheckPeriod);
  ASSERT_EQ(resets_.size(), 1u);
  scheduler_.Advance(ExternalAdoption::kRetry - 2 * ExternalAdoption::kCheckPeriod);
  EXPECT_EQ(resets_.size(), 1u);
  scheduler_.Advance(2 * ExternalAdoption::kCheckPeriod);
  EXPECT_EQ(resets_.size(), 2u);
}

TEST_F(ExternalAdoptionTest, ANodeThatIsNotAttachedIsNeverReset) {
  scheduler_.Advance(60s);
  EXPECT_TRUE(resets_.empty());
  // Attached briefly, gone again before the grace time ends: the grace time starts over.
  attached_.insert("remote-8");
  scheduler_.Advance(ExternalAdoption::kGrace - ExternalAdoption::kCheckPeriod);
  attached_.clear();
  scheduler_.Advance(ExternalAdoption::kCheckPeriod);
  attached_.insert("remote-8");
  scheduler_.Advance(ExternalAdoption::kGrace - ExternalAdoption::kCheckPeriod);
  EXPECT_TRUE(resets_.empty());
}

}  // namespace
}  // namespace canfleet::fleet

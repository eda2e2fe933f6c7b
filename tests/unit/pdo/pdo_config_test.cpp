// PDO parameter write rules: CiA 301 v4.2 §7.5.2.35/§7.5.2.37 (communication parameters) and
// §7.5.2.36/§7.5.2.38 (mapping, dummy entries per §7.4.7.1); facts §4 (CANopenNode `301/CO_PDO.c`, LELY
// `src/co/tpdo.c`). Every refusal leaves the value unchanged.
#include "tests/unit/pdo/pdo_fixture.hpp"

namespace canfleet::canopen::test_pdo {
namespace {

// Sub2: 241–251 are reserved; RTR-only types 252/253 exist for TPDOs only and need RTR allowed.
TEST_F(PdoTest, TransmissionTypeRules) {
  Start();
  EXPECT_EQ(W8(0x1800, 2, 241), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1800, 2, 251), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1800, 2, 252), SdoAbort::kInvalidValue);  // COB-ID bit 30: no RTR
  EXPECT_EQ(W8(0x1800, 2, 253), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1800, 2, 0), SdoAbort::kNone);  // the type may change while valid
  EXPECT_EQ(W8(0x1800, 2, 240), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1800, 2, 254), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1400, 2, 252), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1400, 2, 253), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1400, 2, 245), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1400, 2, 0), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1400, 2, 254), SdoAbort::kNone);

  // Allowing RTR keeps the CAN-ID, so it is allowed while valid; then 252 is accepted, and RTR can
  // no longer be forbidden while the type needs it.
  EXPECT_EQ(W32(0x1800, 1, 0x00000185), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1800, 2, 252), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1800, 2, 253), SdoAbort::kNone);
  EXPECT_EQ(W32(0x1800, 1, 0x40000185), SdoAbort::kInvalidValue);
  EXPECT_EQ(od.GetUnsigned(0x1800, 1), 0x00000185u);
  EXPECT_EQ(od.GetUnsigned(0x1800, 2), 253u);
}

// Sub1: the CAN-ID (and frame format) cannot change while the PDO is and stays valid; restricted
// CAN-IDs cannot be made valid; bits 28–11 must be 0 for an 11-bit CAN-ID.
TEST_F(PdoTest, CobIdRules) {
  Start();
  EXPECT_EQ(W32(0x1800, 1, 0x40000186), SdoAbort::kInvalidValue);
  EXPECT_EQ(W32(0x1800, 1, 0x60000185), SdoAbort::kInvalidValue);  // 29-bit 185h is another identifier
  EXPECT_EQ(W32(0x1800, 1, 0xC0000186), SdoAbort::kNone);          // disable and move at once
  EXPECT_EQ(W32(0x1800, 1, 0x40000186), SdoAbort::kNone);
  EXPECT_EQ(od.GetUnsigned(0x1800, 1), 0x40000186u);

  ASSERT_EQ(W32(0x1401, 1, 0xC0000305), SdoAbort::kNone);
  for (std::uint32_t id :
       {0x000u, 0x07Fu, 0x101u, 0x180u, 0x581u, 0x5FFu, 0x601u, 0x67Fu, 0x6E0u, 0x6FFu, 0x701u, 0x7FFu}) {
    EXPECT_EQ(W32(0x1401, 1, 0x40000000 | id), SdoAbort::kInvalidValue) << std::hex << id;
    EXPECT_EQ(W32(0x1401, 1, 0xC0000000 | id), SdoAbort::kNone) << std::hex << id;  // not valid: allowed
  }
  EXPECT_EQ(W32(0x1401, 1, 0x40000080), SdoAbort::kNone);  // 080h is not restricted for PDOs
  EXPECT_EQ(W32(0x1401, 1, 0xC0000800), SdoAbort::kInvalidValue);
  EXPECT_EQ(W32(0x1401, 1, 0xD0000000), SdoAbort::kInvalidValue);
  EXPECT_EQ(W32(0x1401, 1, 0xE0000800), SdoAbort::kNone);  // 29-bit CAN-ID 800h
  EXPECT_EQ(W32(0x1401, 1, 0x60000800), SdoAbort::kNone);
  EXPECT_EQ(W32(0x1401, 1, 0x60000001), SdoAbort::kInvalidValue);  // valid and stays valid
}

// Sub3 (inhibit time) and sub6 (SYNC start value) may only be written while the PDO is not valid;
// sub6 is 0..240. Sub5 (event timer) may be written at any time.
TEST_F(PdoTest, InhibitTimeAndSyncStartOnlyWhileNotValid) {
  Start();
  EXPECT_EQ(W16(0x1800, 3, 10), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1800, 6, 1), SdoAbort::kInvalidValue);
  EXPECT_EQ(W16(0x1400, 3, 10), SdoAbort::kInvalidValue);
  EXPECT_EQ(W16(0x1800, 5, 100), SdoAbort::kNone);
  EXPECT_EQ(W16(0x1400, 5, 100), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1800, 1, 0xC0000185), SdoAbort::kNone);
  EXPECT_EQ(W16(0x1800, 3, 10), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1800, 6, 241), SdoAbort::kInvalidValue);
  EXPECT_EQ(W8(0x1800, 6, 240), SdoAbort::kNone);
  EXPECT_EQ(od.GetUnsigned(0x1800, 3), 10u);
  EXPECT_EQ(od.GetUnsigned(0x1800, 6), 240u);
}

// Facts §4 "changing a mapping", step by step, with the abort of each broken step.
TEST_F(PdoTest, TpdoMappingProcedureAndAborts) {
  Start();
  Operational();
  // Step 1 skipped: the mapping of a valid PDO cannot change.
  EXPECT_EQ(W8(0x1A00, 0, 0), SdoAbort::kInvalidValue);
  EXPECT_EQ(W32(0x1A00, 1, 0x60000108), SdoAbort::kInvalidValue);
  ASSERT_EQ(W32(0x1800, 1, 0xC0000185), SdoAbort::kNone);  // step 1

  // Entries are checked when written.
  EXPECT_EQ(W32(0x1A00, 1, 0x12340008), SdoAbort::kNoObject);
  EXPECT_EQ(W32(0x1A00, 1, 0x71000910), SdoAbort::kNoSubIndex);
  EXPECT_EQ(W32(0x1A00, 1, 0x20000020), SdoAbort::kNotMappable);  // not PDO-mappable
  EXPECT_EQ(W32(0x1A00, 1, 0x20010010), SdoAbort::kNotMappable);  // write-only: no TPDO
  EXPECT_EQ(W32(0x1A00, 1, 0x20200018), SdoAbort::kNotMappable);  // variable length
  EXPECT_EQ(W32(0x1A00, 1, 0x71000120), SdoAbort::kNotMappable);  // 32 bits of an INTEGER16
  EXPECT_EQ(W32(0x1A00, 1, 0x71000100), SdoAbort::kNotMappable);  // 0 bits
  EXPECT_EQ(W32(0x1A00, 1, 0x00050008), SdoAbort::kNotMappable);  // dummy: RPDO only
  EXPECT_EQ(od.GetUnsigned(0x1A00, 1), 0u);

  // Step 3 while sub0 ≠ 0.
  ASSERT_EQ(W32(0x1A00, 1, 0x60000108), SdoAbort::kNone);
  ASSERT_EQ(W8(0x1A00, 0, 1), SdoAbort::kNone);
  EXPECT_EQ(W32(0x1A00, 2, 0x71000110), SdoAbort::kInvalidValue);
  ASSERT_EQ(W8(0x1A00, 0, 0), SdoAbort::kNone);  // step 2

  // Step 4 checks every entry 1..n and the total length.
  ASSERT_EQ(W32(0x1A00, 1, 0x20300040), SdoAbort::kNone);  // UNSIGNED64, 64 bits
  ASSERT_EQ(W32(0x1A00, 2, 0x60000108), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1A00, 0, 2), SdoAbort::kPdoLengthExceeded);
  EXPECT_EQ(W8(0x1A00, 0, 9), SdoAbort::kInvalidValue);  // only 8 entries exist
  EXPECT_EQ(W8(0x1A00, 0, 65), SdoAbort::kInvalidValue);
  ASSERT_EQ(od.Write(0x1A00, 3, EncodeLe<std::uint32_t>(0x20000020), Origin::kDevice), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1A00, 1, 0x71000110), SdoAbort::kNone);
  EXPECT_EQ(W8(0x1A00, 0, 3), SdoAbort::kNotMappable);  // entry 3 was never checked
  EXPECT_EQ(od.GetUnsigned(0x1A00, 0), 0u);

  // The full procedure, then the PDO sends the new layout.
  ASSERT_EQ(W8(0x1A00, 0, 2), SdoAbort::kNone);            // step 4: AI1 (16 bits) + DI (8 bits)
  ASSERT_EQ(W32(0x1800, 1, 0x40000185), SdoAbort::kNone);  // step 5
  Set(0x7100, 1, -2);
  Set(0x6000, 1, 0x81);
  pdo->RequestTpdo(1);
  EXPECT_EQ(master.Take(), (Frames{"185#FEFF81"}));
}

// RPDO mapping (§7.5.2.36, §7.4.7.1): the objects must be writable; dummy entries (data type index, sub 0)
// skip received bits and are as long as at most their type.
TEST_F(PdoTest, RpdoMappingAbortsAndDummyEntries) {
  Start();
  ASSERT_EQ(W32(0x1400, 1, 0xC0000205), SdoAbort::kNone);
  EXPECT_EQ(W32(0x1600, 1, 0x60000108), SdoAbort::kNotMappable);  // read-only input
  EXPECT_EQ(W32(0x1600, 1, 0x71000110), SdoAbort::kNotMappable);
  EXPECT_EQ(W32(0x1600, 1, 0x00050010), SdoAbort::kNotMappable);  // 16 bits of an UNSIGNED8 dummy
  EXPECT_EQ(W32(0x1600, 1, 0x00050108), SdoAbort::kNoObject);     // dummy needs sub-index 0
  EXPECT_EQ(W32(0x1600, 1, 0x20010010), SdoAbort::kNone);         // write-only is fine for an RPDO
  EXPECT_EQ(W32(0x1600, 1, 0x00050008), SdoAbort::kNone);
  EXPECT_EQ(W32(0x1600, 2, 0x73000110), SdoAbort::kNone);
  ASSERT_EQ(W8(0x1600, 0, 2), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1400, 1, 0x40000205), SdoAbort::kNone);
  Operational();
  master.Send("205#FF3412");
  EXPECT_EQ(od.GetSigned(0x7300, 1), 0x1234);
  EXPECT_TRUE(errors.events.empty());
}

// Enabling a PDO with nothing mapped is allowed (CANopenNode refuses it): a TPDO then sends
// nothing, an RPDO takes any frame and writes nothing.
TEST_F(PdoTest, EnablingWithNothingMappedIsAllowed) {
  Start();
  ASSERT_EQ(W32(0x1801, 1, 0xC0000285), SdoAbort::kNone);
  ASSERT_EQ(W16(0x1801, 5, 10), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1801, 1, 0x40000285), SdoAbort::kNone);
  ASSERT_EQ(W8(0x1801, 2, 254), SdoAbort::kNone);
  Operational();
  pdo->RequestTpdo(2);
  scheduler.Advance(100ms);
  master.Send("205#0102");
  EXPECT_EQ(recorder.Take(), (Frames{"100ms 205#0102"}));  // only the master's frame
  EXPECT_EQ(consumed, (std::vector<bool>{true}));
  EXPECT_EQ(pdo->Counters().rpdo_received, 1u);
  EXPECT_EQ(pdo->Counters().tpdo_sent, 0u);
  EXPECT_TRUE(errors.events.empty());
}

// A device default that names a missing object makes the PDO unusable (CANopenNode: erroneous
// mapping) until the mapping is fixed; it does not stop the other PDOs.
TEST_F(PdoTest, BrokenDefaultMappingDisablesOnlyThatPdo) {
  od.Find(0x1A00, 0)->value = {1};
  od.Find(0x1A00, 1)->value = EncodeLe<std::uint32_t>(0x5FFF0008);
  od.Find(0x1A01, 0)->value = {1};
  od.Find(0x1A01, 1)->value = EncodeLe<std::uint32_t>(0x60000108);
  Start();
  Operational();
  pdo->RequestTpdo(1);
  pdo->RequestTpdo(2);
  EXPECT_EQ(master.Take(), (Frames{"285#00"}));
  ASSERT_EQ(W32(0x1800, 1, 0xC0000185), SdoAbort::kNone);
  ASSERT_EQ(W8(0x1A00, 0, 0), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1A00, 1, 0x60000108), SdoAbort::kNone);
  ASSERT_EQ(W8(0x1A00, 0, 1), SdoAbort::kNone);
  ASSERT_EQ(W32(0x1800, 1, 0x40000185), SdoAbort::kNone);
  pdo->RequestTpdo(1);
  EXPECT_EQ(master.Take(), (Frames{"185#00"}));
}

// Empty entries (00000000h) pad a mapping, as in the power supply's defaults (sub0 = 4 with two
// entries): they take no bits.
TEST_F(PdoTest, EmptyEntriesTakeNoBits) {
  Start();
  Tpdo(1, {.entries = {0x60000108, 0x00000000, 0x62000108, 0x00000000}});
  Operational();
  Set(0x6000, 1, 0x11);
  Set(0x6200, 1, 0x22);
  pdo->RequestTpdo(1);
  EXPECT_EQ(master.Take(), (Frames{"185#1122"}));
}

}  // namespace
}  // namespace canfleet::canopen::test_pdo

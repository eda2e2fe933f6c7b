// Dictionary tables (node/devices/dictionary/FORMAT.md): rows, runs, lists, loops and facts, and a
// located error for every kind of bad input.
#include "node/devices/dictionary/od_table.hpp"

#include <gtest/gtest.h>

#include <string>

#include "node/canopen/od/value.hpp"

namespace canfleet::devices {
namespace {

using canopen::Access;
using canopen::DataType;
using canopen::ObjectCode;

constexpr std::string_view kHeader =
    "| index | kind | name | type | access | pdo | default | low | high | manual |\n"
    "|---|---|---|---|---|---|---|---|---|---|\n";

canopen::EdsFile Parse(const std::string& rows) {
  return ParseOdTable(std::string(kHeader) + rows, "t.od");
}

std::string ErrorOf(const std::string& text) {
  try {
    (void)ParseOdTable(text, "t.od");
  } catch (const OdTableError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(OdTable, AVarRowIsAnObjectWithSubIndexZero) {
  const auto eds =
      Parse("| 1017 | VAR | Producer Heartbeat Time | UNSIGNED16 | rw | 0 | 500 | 10 | 65535 | 3.2.7 |\n");
  const auto* sub = eds.od.Find(0x1017, 0);
  ASSERT_NE(sub, nullptr);
  EXPECT_EQ(eds.od.Find(0x1017)->code, ObjectCode::kVar);
  EXPECT_EQ(sub->name, "Producer Heartbeat Time");
  EXPECT_EQ(sub->type, DataType::kUnsigned16);
  EXPECT_EQ(sub->access, Access::kRw);
  EXPECT_EQ(canopen::DecodeUnsignedLe(sub->default_value), 500u);
  EXPECT_EQ(canopen::DecodeUnsignedLe(sub->value), 500u);
  EXPECT_EQ(canopen::DecodeUnsignedLe(*sub->low_limit), 10u);
  EXPECT_EQ(canopen::DecodeUnsignedLe(*sub->high_limit), 65535u);
}

// Found by fuzz/od_table: the VAR's sub-index 0 was named "a0" while the object was "a{n}", so
// the EDS (one ParameterName per VAR, CiA 306 §4.5.2) read back differently.
TEST(OdTable, AVarsNameIsTakenAsWrittenEvenWithARunPlaceholder) {
  const auto eds = Parse("| 2000 | VAR | a{n} | U8 | rw | 0 | 0 | | | 3 |\n");
  EXPECT_EQ(eds.od.Find(0x2000)->name, "a{n}");
  EXPECT_EQ(eds.od.Find(0x2000, 0)->name, "a{n}");
}

TEST(OdTable, ARunGivesEverySubItsNameAndItsValueFromTheList) {
  const auto eds = Parse(
      "| 6110 | ARRAY | AI Sensor Type | | | | | | | 3.4.5 |\n"
      "| 6110 | 0 | Highest sub-index supported | UNSIGNED8 | ro | 0 | 12 | | | |\n"
      "| 6110 | 1..12 | AI Sensor Type {n} ({i}) | UNSIGNED16 | rw | 1 | 40*7,10000*5 | | | |\n");
  const auto* object = eds.od.Find(0x6110);
  ASSERT_NE(object, nullptr);
  EXPECT_EQ(object->code, ObjectCode::kArray);
  EXPECT_EQ(object->subs.size(), 13u);
  EXPECT_EQ(object->subs.at(7).name, "AI Sensor Type 7 (7)");
  EXPECT_EQ(canopen::DecodeUnsignedLe(object->subs.at(7).default_value), 40u);
  EXPECT_EQ(canopen::DecodeUnsignedLe(object->subs.at(8).default_value), 10000u);
  EXPECT_TRUE(object->subs.at(12).pdo_mappable);
}

TEST(OdTable, LoopsExpandWithZeroPaddedValuesAndNest) {
  const auto eds = Parse(
      "@for yz 01..12\n"
      "| 3{yz}0 | VAR | LT{yz} X-Axis Source | U8 | rw | 0 | 0 | 0 | 11 | 3.4.62 |\n"
      "@end\n"
      "@for x 4..5 lb 1..2\n"
      "@for y 1..3\n"
      "| 3{x}{y}1 | VAR | LB{lb} Function {y} | U8 | rw | 0 | {y} | | | 3.4.84 |\n"
      "@end\n"
      "@end\n");
  EXPECT_NE(eds.od.Find(0x3010), nullptr);
  EXPECT_NE(eds.od.Find(0x3120), nullptr);
  EXPECT_EQ(eds.od.Find(0x3100)->name, "LT10 X-Axis Source");
  EXPECT_EQ(eds.od.Find(0x3531)->subs.at(0).name, "LB2 Function 3");
  EXPECT_EQ(canopen::DecodeUnsignedLe(eds.od.Find(0x3421)->subs.at(0).default_value), 2u);
}

TEST(OdTable, NodeIdDefaultsRealsAndStrings) {
  const auto eds = Parse(
      "| 1014 | VAR | COB-ID EMCY | UNSIGNED32 | ro | 0 | $NODEID+0x80 | | | 3.2.4 |\n"
      "| 5010 | VAR | Constant | REAL32 | rw | 0 | 3.141593 | | | 3.4.98 |\n"
      "| 1008 | VAR | Device name | VISIBLE_STRING | const | 0 | valve, 12 in | | | 3.2.2 |\n");
  EXPECT_TRUE(eds.od.Find(0x1014, 0)->default_adds_node_id);
  EXPECT_EQ(canopen::DecodeUnsignedLe(eds.od.Find(0x1014, 0)->default_value), 0x80u);
  EXPECT_EQ(eds.od.Find(0x5010, 0)->default_value.size(), 4u);
  const auto& text = eds.od.Find(0x1008, 0)->default_value;
  EXPECT_EQ(std::string(text.begin(), text.end()), "valve, 12 in");
}

TEST(OdTable, FactsFillTheFileAndDeviceSectionsAndPdoCountsAreDerived) {
  const auto eds = Parse(
      "@file_name v.eds\n@vendor_number 0x55\n@baud_rates 125 250 1000\n@lss_supported 1\n"
      "@dummy_usage 0002 0005\n@comment first line\n@comment second\n"
      "| 1400 | RECORD | RPDO1 | | | | | | | 3.2.12 |\n"
      "| 1400 | 0 | Highest sub-index supported | U8 | ro | 0 | 2 | | | |\n"
      "| 1400 | 1 | COB-ID | U32 | rw | 0 | $NODEID+0x200 | | | |\n"
      "| 1400 | 2 | Type | U8 | ro | 0 | 255 | | | |\n");
  EXPECT_EQ(eds.file_info.file_name, "v.eds");
  EXPECT_EQ(eds.device_info.vendor_number, 0x55u);
  EXPECT_EQ(eds.device_info.baud_rates_kbit, (std::set<std::uint16_t>{125, 250, 1000}));
  EXPECT_TRUE(eds.device_info.lss_supported);
  EXPECT_EQ(eds.dummy_usage, (1u << 2) | (1u << 5));
  EXPECT_EQ(eds.comments, (std::vector<std::string>{"first line", "second"}));
  EXPECT_EQ(eds.device_info.nr_of_rx_pdo, 1u);
  EXPECT_EQ(eds.device_info.nr_of_tx_pdo, 0u);
}

struct BadCase {
  const char* text;
  const char* message;
};

class OdTableBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(OdTableBadInput, IsALocatedError) {
  EXPECT_EQ(ErrorOf(GetParam().text), GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, OdTableBadInput,
    ::testing::Values(
        BadCase{"| 1000 | VAR | x | U32 | ro | 0 | 0x1G | | | 3 |\n",
                "t.od:1: column \"default\": \"0x1G\" is not a number"},
        BadCase{"\n\n| 100 | VAR | x | U32 | ro | 0 | 0 | | | 3 |\n",
                "t.od:3: column \"index\": \"100\" is not an index of 4 hex digits"},
        BadCase{
            "| 1000 | VAR | x | U33 | ro | 0 | 0 | | | 3 |\n",
            "t.od:1: column \"type\": \"U33\" is not a CiA 301 data type (UNSIGNED8, INTEGER16, REAL32...)"},
        BadCase{
            "| 1000 | VAR | x | U32 | ro | 0 | 0 | | 3 |\n",
            "t.od:1: a row has 10 cells (index | kind | name | type | access | pdo | default | low | high | "
            "manual), this one 9"},
        BadCase{"| 1000 | VAR | x | U32 | ro | 0 | 0 | | | |\n",
                "t.od:1: column \"manual\": an object row cites its manual section"},
        BadCase{"| 2000 | 1 | x | U8 | ro | 0 | 0 | | | |\n",
                "t.od:1: column \"index\": sub-objects of 2000h come after its ARRAY or RECORD row"},
        BadCase{"| 2000 | ARRAY | a | | | | | | | 3 |\n| 2000 | 0 | n | U8 | ro | 0 | 3 | | | |\n"
                "| 2000 | 1..2 | e{n} | U8 | rw | 0 | 1,2,3 | | | |\n",
                "t.od:3: column \"default\": the list gives more than 2 values"},
        BadCase{"| 2000 | ARRAY | a | | | | | | | 3 |\n| 2000 | 0 | n | U8 | ro | 0 | 3 | | | |\n"
                "| 2000 | 1..2 | e{n} | U8 | rw | 0 | 1 | | | |\n",
                "t.od:1: column \"kind\": 2000h sub-index 0 says 3 but the highest sub-index is 2"},
        BadCase{"| 2000 | VAR | a | U8 | rw | 2 | 0 | | | 3 |\n",
                "t.od:1: column \"pdo\": \"2\" is not 0 or 1"},
        BadCase{"| 2000 | VAR | a | U8 | rw | 0 | 300 | | | 3 |\n",
                "t.od:1: column \"default\": \"300\" is out of range for UNSIGNED8 (0..255)"},
        BadCase{"@for x 1..3\n| 2000 | VAR | a | U8 | rw | 0 | 0 | | | 3 |\n", "t.od:1: @for without @end"},
        BadCase{"@end\n", "t.od:1: @end without @for"},
        BadCase{"@for x 3..1\n@end\n",
                "t.od:1: @for range \"3..1\" is not FIRST..LAST (decimal, at most 1000 values)"},
        BadCase{"@for x 1..2\n| 2000 | VAR | a | U8 | rw | 0 | 0 | | | 3 |\n@end\n",
                "t.od:2: column \"index\": object 2000h is defined twice"},
        BadCase{"@vendor x\n",
                "t.od:1: unknown fact \"@vendor\" (known: @baud_rates, @comment, @created_by, "
                "@creation_date, @creation_time, @description, @dummy_usage, @dynamic_channels_supported, "
                "@file_name, @file_revision, @file_version, @granularity, @group_messaging, "
                "@lss_supported, @modification_date, @modification_time, @modified_by, @nr_of_rx_pdo, "
                "@nr_of_tx_pdo, @order_code, @product_name, @product_number, @revision_number, "
                "@simple_boot_up_master, @simple_boot_up_slave, @vendor_name, @vendor_number)"},
        BadCase{"@baud_rates 125 300\n",
                "t.od:1: column \"@baud_rates\": 300 kbit/s is not a CiA 306 BaudRate_ key"},
        // Found by fuzz/od_table: a date the EDS reader refuses must not reach the generated EDS.
        BadCase{"@creation_date 01-15-2025\x8d\n",
                "t.od:1: column \"@creation_date\": \"01-15-2025\x8d\" is not a date (mm-dd-yyyy)"},
        BadCase{"@modification_time 9:00 o'clock\n",
                "t.od:1: column \"@modification_time\": \"9:00 o'clock\" is not a time (hh:mmAM)"},
        // Found by fuzz/od_table: a name with a control character gave an EDS that cannot be written.
        BadCase{"| 2000 | VAR | a\x04"
                "b | U8 | rw | 0 | 0 | | | 3 |\n",
                "t.od:1: a control character (04h) in a line: tables are text"},
        // Found by fuzz/od_table: a limit on a string was kept in the table, dropped by the EDS
        // reader (CiA 306 limits bound numbers), so the generated EDS read back differently.
        BadCase{"| 6110 | VAR | s | VISIBLE_STRING | rw | 0 | x | \xff | | 3 |\n",
                "t.od:1: column \"low\": a limit bounds a number; VISIBLE_STRING has none"},
        BadCase{"| 6110 | VAR | d | DOMAIN | rw | 0 | | | 1 | 3 |\n",
                "t.od:1: column \"high\": a limit bounds a number; DOMAIN has none"},
        BadCase{"just words\n",
                "t.od:1: a line is a row (|...|), a fact (@key value), @for/@end or a # comment"},
        BadCase{"# nothing\n", "t.od:0: the table has no objects"}));

}  // namespace
}  // namespace canfleet::devices

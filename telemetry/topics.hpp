#pragma once
/// @file The seven fleet topics: names, descriptors and QoS profiles (reasons in telemetry/QOS.md).

#include <cstdint>

#include "canfleet_telemetry.h"
#include "telemetry/dds.hpp"

namespace canfleet::telemetry {

/// History kept per instance of an event topic (Emcy per node, FaultEvent per bus), by the writer
/// for late joiners and by readers.
inline constexpr std::int32_t kEventHistoryDepth = 32;

/// State topics (NodeStatus, IoSnapshot, BusStats): reliable, keep-last 1, transient-local.
QosPtr StateQos();
/// Event topics (Emcy, FaultEvent): reliable, keep-last kEventHistoryDepth, transient-local with
/// the same depth in durability_service (Cyclone keeps that many per instance for late joiners).
QosPtr EventQos();
/// Readers: the writers' profile; readers never apply back-pressure (keep-last, not keep-all).
QosPtr StateReaderQos();
QosPtr EventReaderQos();

template <>
struct TopicTraits<canfleet_telemetry_NodeStatus> {
  static constexpr const char* kName = "canfleet_NodeStatus";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_NodeStatus_desc; }
  static QosPtr Qos() { return StateQos(); }
  static QosPtr ReaderQos() { return StateReaderQos(); }
};

template <>
struct TopicTraits<canfleet_telemetry_IoSnapshot> {
  static constexpr const char* kName = "canfleet_IoSnapshot";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_IoSnapshot_desc; }
  static QosPtr Qos() { return StateQos(); }
  static QosPtr ReaderQos() { return StateReaderQos(); }
};

template <>
struct TopicTraits<canfleet_telemetry_BusStats> {
  static constexpr const char* kName = "canfleet_BusStats";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_BusStats_desc; }
  static QosPtr Qos() { return StateQos(); }
  static QosPtr ReaderQos() { return StateReaderQos(); }
};

template <>
struct TopicTraits<canfleet_telemetry_Emcy> {
  static constexpr const char* kName = "canfleet_Emcy";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_Emcy_desc; }
  static QosPtr Qos() { return EventQos(); }
  static QosPtr ReaderQos() { return EventReaderQos(); }
};

template <>
struct TopicTraits<canfleet_telemetry_FaultEvent> {
  static constexpr const char* kName = "canfleet_FaultEvent";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_FaultEvent_desc; }
  static QosPtr Qos() { return EventQos(); }
  static QosPtr ReaderQos() { return EventReaderQos(); }
};

/// A verdict is an event, but keyed by (source, index) with keep-last 1: a late joiner gets the
/// latest verdict of every expectation, not every cycle's (telemetry/QOS.md).
template <>
struct TopicTraits<canfleet_telemetry_Verdict> {
  static constexpr const char* kName = "canfleet_Verdict";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_Verdict_desc; }
  static QosPtr Qos() { return StateQos(); }
  static QosPtr ReaderQos() { return StateReaderQos(); }
};

template <>
struct TopicTraits<canfleet_telemetry_ScenarioStatus> {
  static constexpr const char* kName = "canfleet_ScenarioStatus";
  static const dds_topic_descriptor_t& Descriptor() { return canfleet_telemetry_ScenarioStatus_desc; }
  static QosPtr Qos() { return StateQos(); }
  static QosPtr ReaderQos() { return StateReaderQos(); }
};

}  // namespace canfleet::telemetry

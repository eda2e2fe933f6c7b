#include "node/devices/datalogger_tc_analog/program_blocks.hpp"

#include <algorithm>

namespace canfleet::devices::datalogger {

namespace {

using blocks::SourceKind;
using canopen::ObjectDictionary;
using canopen::Origin;
using canopen::SdoAbort;
using canopen::SubObject;

std::int64_t Decode(const SubObject& sub, std::span<const std::uint8_t> data) {
  if (canopen::IsSigned(sub.type)) return canopen::DecodeSignedLe(data);
  return static_cast<std::int64_t>(canopen::DecodeUnsignedLe(data));
}

std::uint8_t U8(const OdRef& ref) {
  return static_cast<std::uint8_t>(ref.Get());
}

// The time response's longest point (§1.5.4: "1ms to 24 hours").
constexpr std::int64_t kMaxTimePoint = 86'400'000;

}  // namespace

ProgramBlocks::ProgramBlocks(ObjectDictionary& od, blocks::SignalResolver inputs)
    : inputs_(std::move(inputs)),
      sources_(blocks::DataLoggerSourceTypes(),
               [this](SourceKind kind, std::uint8_t number) { return Resolve(kind, number); }),
      math_profile_(blocks::DataLoggerMathProfile()) {
  for (int n = 1; n <= kLookupTables; ++n) {
    TableSlot& t = tables_[static_cast<std::size_t>(n - 1)];
    const std::uint16_t base = LutBase(n);
    t.source = OdRef(od, base + kLutSource, 0);
    t.number = OdRef(od, base + kLutNumber, 0);
    t.auto_repeat = OdRef(od, base + kLutAutoRepeat, 0);
    t.y_digits = OdRef(od, base + kLutYDigits, 0);
    t.x_type = OdRef(od, base + kLutResponse, 1);
    for (int k = 0; k < kLutPoints; ++k) {
      const auto sub = static_cast<std::uint8_t>(k + 1);
      t.x[static_cast<std::size_t>(k)] = OdRef(od, base + kLutX, sub);
      t.y[static_cast<std::size_t>(k)] = OdRef(od, base + kLutY, sub);
      t.response[static_cast<std::size_t>(k)] = OdRef(od, base + kLutResponse, sub);
    }
    t.output = OdRef(od, base + kLutOutput, 0);
    t.params = blocks::DefaultLookupTableParams(t.block.profile());
  }
  for (int n = 1; n <= kMathBlocks; ++n) {
    MathSlot& m = maths_[static_cast<std::size_t>(n - 1)];
    const auto sub = static_cast<std::uint8_t>(n);
    const std::uint16_t base = MathBase(n);
    m.enable = OdRef(od, kMathEnable, sub);
    m.scaling1 = OdRef(od, kMathOutputScaling1, sub);
    m.scaling2 = OdRef(od, kMathOutputScaling2, sub);
    m.digits = OdRef(od, kMathOutputDigits, sub);
    m.output = OdRef(od, kMathOutput, sub);
    for (int k = 0; k < kMathInputs; ++k) {
      const auto in = static_cast<std::uint8_t>(k + 1);
      MathInput& i = m.inputs[static_cast<std::size_t>(k)];
      i.source = OdRef(od, base + kMathSource, in);
      i.number = OdRef(od, base + kMathNumber, in);
      i.function = OdRef(od, base + kMathFunctionNumber, in);
      i.digits = OdRef(od, base + kMathInputDigits, in);
      i.scaling1 = OdRef(od, base + kMathInputScaling1, in);
      i.scaling2 = OdRef(od, base + kMathInputScaling2, in);
      i.gain = OdRef(od, base + kMathGain, in);
    }
    for (int k = 0; k < kMathFunctions; ++k)
      m.operators[static_cast<std::size_t>(k)] =
          OdRef(od, base + kMathOperator, static_cast<std::uint8_t>(k + 1));
    m.block = std::make_unique<blocks::MathBlock>(math_profile_, sub);
    m.params = blocks::DefaultMathBlockParams(math_profile_);
  }
  for (int n = 1; n <= kLogicBlocks; ++n) {
    LogicSlot& l = logics_[static_cast<std::size_t>(n - 1)];
    const auto sub = static_cast<std::uint8_t>(n);
    l.enable = OdRef(od, kLogicEnable, sub);
    l.selected = OdRef(od, kLogicSelectedTable, sub);
    l.output = OdRef(od, kLogicOutput, sub);
    for (int f = 1; f <= 3; ++f) {
      const auto fs = static_cast<std::uint8_t>(f);
      l.tables[static_cast<std::size_t>(f - 1)] = OdRef(od, LogicBase(n) + kLogicTables, fs);
      l.operators[static_cast<std::size_t>(f - 1)] = OdRef(od, LogicBase(n) + kLogicOperators, fs);
      for (int c = 1; c <= 3; ++c) {
        const std::uint16_t index = LogicCondition(n, f, c);
        Condition& cond = l.conditions[static_cast<std::size_t>(f - 1)][static_cast<std::size_t>(c - 1)];
        cond.arg1_source = OdRef(od, index, 1);
        cond.arg1_number = OdRef(od, index, 2);
        cond.arg2_source = OdRef(od, index, 3);
        cond.arg2_number = OdRef(od, index, 4);
        cond.op = OdRef(od, index, 5);
      }
    }
    l.params = blocks::DefaultLogicBlockParams(sub);
  }
}

blocks::Signal ProgramBlocks::Resolve(SourceKind kind, std::uint8_t number) const {
  switch (kind) {
    case SourceKind::kLookupTable:
      if (number >= 1 && number <= kLookupTables) return tables_[number - 1u].block.Output();
      return blocks::Signal::NotAvailable();
    case SourceKind::kMath:
      if (number >= 1 && number <= kMathBlocks) return maths_[number - 1u].block->Output();
      return blocks::Signal::NotAvailable();
    case SourceKind::kLogic:
      if (number >= 1 && number <= kLogicBlocks) return logics_[number - 1u].block.Output();
      return blocks::Signal::NotAvailable();
    default:
      return inputs_ ? inputs_(kind, number) : blocks::Signal::NotAvailable();
  }
}

void ProgramBlocks::ReadTable(TableSlot& t) {
  t.params.x_axis_type = t.x_type.Get() == 1 ? blocks::XAxisType::kTime : blocks::XAxisType::kData;
  t.params.auto_repeat = t.auto_repeat.Get() != 0;
  t.params.y_digits = U8(t.y_digits);
  t.params.points.resize(kLutPoints);
  for (std::size_t k = 0; k < kLutPoints; ++k) {
    blocks::LutPoint& p = t.params.points[k];
    p.x = static_cast<double>(t.x[k].Get());
    p.y = static_cast<double>(t.y[k].Get());
    p.response =
        k == 0 ? blocks::PointResponse::kRampTo
               : t.block.profile().DecodeResponse(U8(t.response[k])).value_or(blocks::PointResponse::kRampTo);
  }
}

void ProgramBlocks::ReadMath(MathSlot& m) {
  m.params.enabled = m.enable.Get() != 0;
  m.params.output_scaling1 = static_cast<double>(m.scaling1.Get());
  m.params.output_scaling2 = static_cast<double>(m.scaling2.Get());
  m.params.output_digits = U8(m.digits);
  m.params.inputs.resize(kMathInputs);
  for (std::size_t k = 0; k < kMathInputs; ++k) {
    const MathInput& in = m.inputs[k];
    blocks::MathInputParams& p = m.params.inputs[k];
    p.source = {U8(in.source), U8(in.number)};
    p.function = U8(in.function);
    p.decimal_digits = U8(in.digits);
    p.scaling1 = static_cast<double>(in.scaling1.Get());
    p.scaling2 = static_cast<double>(in.scaling2.Get());
    p.gain = static_cast<double>(in.gain.Get()) / 100.0;  // 4y40h: 2 fixed decimals
  }
  m.params.operators.resize(kMathFunctions);
  for (std::size_t k = 0; k < kMathFunctions; ++k)
    m.params.operators[k] = U8(m.operators[k]);
}

void ProgramBlocks::ReadLogic(LogicSlot& l) {
  l.params.enabled = l.enable.Get() != 0;
  for (std::size_t f = 0; f < 3; ++f) {
    blocks::LogicFunction& fn = l.params.functions[f];
    fn.table = U8(l.tables[f]);
    fn.op =
        blocks::DecodeFunctionOperator(U8(l.operators[f])).value_or(blocks::FunctionOperator::kDefaultTable);
    for (std::size_t c = 0; c < 3; ++c) {
      const Condition& cond = l.conditions[f][c];
      blocks::LogicCondition& lc = fn.conditions[c];
      lc.arg1 = {U8(cond.arg1_source), U8(cond.arg1_number)};
      lc.arg2 = {U8(cond.arg2_source), U8(cond.arg2_number)};
      lc.op = blocks::DecodeCompareOp(U8(cond.op)).value_or(blocks::CompareOp::kEqual);
    }
  }
}

bool ProgramBlocks::Update(std::chrono::milliseconds elapsed) {
  bool changed = false;
  for (MathSlot& m : maths_) {
    ReadMath(m);
    changed |= m.output.SetNumber(m.block->Update(m.params, sources_).value);
  }
  for (TableSlot& t : tables_) {
    ReadTable(t);
    const blocks::Signal x = sources_.Resolve(blocks::SourceRef{U8(t.source), U8(t.number)});
    changed |= t.output.SetNumber(t.block.Update(t.params, x, elapsed).value);
  }
  for (LogicSlot& l : logics_) {
    ReadLogic(l);
    const blocks::LogicResult& r = l.block.Update(l.params, sources_);
    changed |= l.selected.Set(r.table);
    changed |= l.output.SetNumber(r.output.available ? r.output.value : 0.0);
  }
  return changed;
}

std::optional<std::chrono::milliseconds> ProgramBlocks::NextChange() const {
  std::optional<std::chrono::milliseconds> next;
  for (const TableSlot& t : tables_) {
    const auto after = t.block.NextChangeAfter();
    if (after && (!next || *after < *next)) next = after;
  }
  return next;
}

void ProgramBlocks::Reset() {
  for (TableSlot& t : tables_)
    t.block.Reset();
  for (int n = 1; n <= kMathBlocks; ++n)
    maths_[static_cast<std::size_t>(n - 1)].block =
        std::make_unique<blocks::MathBlock>(math_profile_, static_cast<std::uint8_t>(n));
  for (LogicSlot& l : logics_)
    l.block = blocks::LogicBlock{};
}

void ProgramBlocks::InstallHooks(ObjectDictionary& od) {
  // Number objects: inside the range of the source configured now (Table 14).
  const auto number_rule = [this](OdRef source) {
    return [this, source](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
      const blocks::SourceType* type = sources_.Find(static_cast<std::uint8_t>(source.Get()));
      if (type == nullptr || type->number_ignored) return SdoAbort::kNone;
      const std::int64_t v = Decode(s, data);
      if (v < type->first_number) return SdoAbort::kValueTooLow;
      if (v > type->last_number) return SdoAbort::kValueTooHigh;
      return SdoAbort::kNone;
    };
  };
  for (TableSlot& t : tables_)
    t.number.sub().AddValidator(number_rule(t.source));
  for (MathSlot& m : maths_) {
    for (MathInput& in : m.inputs)
      in.number.sub().AddValidator(number_rule(in.source));
  }
  for (LogicSlot& l : logics_) {
    for (auto& function : l.conditions) {
      for (Condition& c : function) {
        c.arg1_number.sub().AddValidator(number_rule(c.arg1_source));
        c.arg2_number.sub().AddValidator(number_rule(c.arg2_source));
      }
    }
  }

  // 3yz6h: monotonic X, inside the source's limits (data) or 1..86 400 000 ms (time).
  for (TableSlot& table : tables_) {
    TableSlot* t = &table;
    for (std::size_t k = 0; k < kLutPoints; ++k) {
      t->x[k].sub().AddValidator(
          [this, t, k](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
            const std::int64_t v = Decode(s, data);
            if (t->x_type.Get() == 1) {
              if (k == 0) return SdoAbort::kNone;  // point 1 is (0 ms, 0) whatever is stored
              if (v < 1) return SdoAbort::kValueTooLow;
              if (v > kMaxTimePoint) return SdoAbort::kValueTooHigh;
              return SdoAbort::kNone;
            }
            ReadTable(*t);
            std::vector<blocks::LutPoint> points = t->params.points;
            points[k].x = static_cast<double>(v);
            if (k >= blocks::UsedPointCount(points)) return SdoAbort::kNone;  // an ignored point
            if (k > 0 && points[k].x < points[k - 1].x) return SdoAbort::kValueTooLow;
            if (k + 1 < blocks::UsedPointCount(points) && points[k].x > points[k + 1].x)
              return SdoAbort::kValueTooHigh;
            const blocks::Signal source = sources_.Resolve(blocks::SourceRef{U8(t->source), U8(t->number)});
            if (source.available && source.has_range && source.min < source.max) {
              if (points[k].x < source.min) return SdoAbort::kValueTooLow;
              if (points[k].x > source.max) return SdoAbort::kValueTooHigh;
            }
            return SdoAbort::kNone;
          });
    }
    // §1.5.4: with a time response "3yz3h ... is automatically set to 0" and point 1 "is
    // automatically set to [0,0]".
    t->x_type.sub().AddListener([t, &od](SubObject& s, Origin origin) {
      if (origin == Origin::kDevice || canopen::DecodeUnsignedLe(s.value) != 1) return;
      const std::uint16_t base = static_cast<std::uint16_t>(s.index - kLutResponse);
      OdRef(od, base + kLutXDigits, 0).Set(0);
      t->x[0].Set(0);
      t->y[0].Set(0);
    });
  }

  // 2520h < 2522h (§3.4.29: "must always be smaller").
  for (int n = 1; n <= kReceivedValues; ++n) {
    const auto sub = static_cast<std::uint8_t>(n);
    OdRef low(od, kReceivedScaling1, sub);
    OdRef high(od, kReceivedScaling2, sub);
    low.sub().AddValidator([high](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
      return Decode(s, data) < high.Get() ? SdoAbort::kNone : SdoAbort::kValueTooHigh;
    });
    high.sub().AddValidator([low](const SubObject& s, std::span<const std::uint8_t> data, Origin) {
      return Decode(s, data) > low.Get() ? SdoAbort::kNone : SdoAbort::kValueTooLow;
    });
  }
}

}  // namespace canfleet::devices::datalogger

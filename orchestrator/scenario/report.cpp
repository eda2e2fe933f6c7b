#include "orchestrator/scenario/report.hpp"

#include <cstdio>

namespace canfleet::scenario {

namespace {

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", s);
  return text;
}

/// How long an expectation took to decide: from its window's opening to its verdict.
double CaseSeconds(const Result& r) {
  if (!r.opened || r.verdict.outcome == Outcome::kPending || r.verdict.time < *r.opened) return 0;
  return std::chrono::duration<double>(r.verdict.time - *r.opened).count();
}

}  // namespace

void Totals::Add(const FileReport& file) {
  if (!file.error.empty()) ++errors;
  for (const auto& r : file.results) {
    ++tests;
    switch (r.verdict.outcome) {
      case Outcome::kPassed:
        ++passed;
        break;
      case Outcome::kFailed:
        ++failed;
        break;
      default:
        ++skipped;
        break;
    }
  }
}

std::string ResultLine(const std::string& file, int line, const Result& result) {
  std::string out = OutcomeName(result.verdict.outcome);
  out.resize(6, ' ');
  out += file;
  if (line > 0) out += ":" + std::to_string(line);
  out += "  " + result.name + ": " + result.description;
  if (!result.verdict.detail.empty()) out += ": " + result.verdict.detail;
  return out;
}

std::string SummaryLine(const Totals& t, std::size_t files, double seconds) {
  char time[32];
  std::snprintf(time, sizeof time, "%.1f s", seconds);
  std::string out = "canfleet test: " + std::string(t.AllPassed() ? "PASSED" : "FAILED") + ", " +
                    std::to_string(t.passed) + " passed, " + std::to_string(t.failed) + " failed, " +
                    std::to_string(t.skipped) + " skipped, " + std::to_string(t.errors) + " errors (" +
                    std::to_string(t.tests) + (t.tests == 1 ? " expectation in " : " expectations in ") +
                    std::to_string(files) + (files == 1 ? " file, " : " files, ") + time + ")";
  return out;
}

std::string XmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        // XML 1.0 allows no control characters but tab, newline and carriage return.
        if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r')
          out += '?';
        else
          out += c;
    }
  }
  return out;
}

void WriteJunit(std::ostream& out, const JunitRun& run) {
  Totals all;
  double seconds = 0;
  for (const auto& f : run.files) {
    all.Add(f);
    seconds += f.seconds;
  }
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out << "<testsuites name=\"canfleet test\" tests=\"" << all.tests + all.errors << "\" failures=\""
      << all.failed << "\" errors=\"" << all.errors << "\" skipped=\"" << all.skipped << "\" time=\""
      << Seconds(seconds) << "\">\n";
  for (const auto& f : run.files) {
    Totals t;
    t.Add(f);
    out << "  <testsuite name=\"" << XmlEscape(f.topology.empty() ? f.file : f.topology) << "\" file=\""
        << XmlEscape(f.file) << "\" tests=\"" << t.tests + t.errors << "\" failures=\"" << t.failed
        << "\" errors=\"" << t.errors << "\" skipped=\"" << t.skipped << "\" time=\"" << Seconds(f.seconds)
        << "\">\n";
    out << "    <properties>\n";
    out << "      <property name=\"time\" value=\"" << XmlEscape(run.time_mode) << "\"/>\n";
    if (run.seed) out << "      <property name=\"seed\" value=\"" << *run.seed << "\"/>\n";
    out << "    </properties>\n";
    const std::string classname = XmlEscape(f.topology.empty() ? f.file : f.topology);
    if (!f.error.empty()) {
      out << "    <testcase name=\"fleet\" classname=\"" << classname << "\" file=\"" << XmlEscape(f.file)
          << "\" time=\"" << Seconds(f.seconds) << "\">\n";
      out << "      <error message=\"" << XmlEscape(f.error) << "\" type=\"fleet\">" << XmlEscape(f.error)
          << "</error>\n";
      out << "    </testcase>\n";
    }
    for (std::size_t i = 0; i < f.results.size(); ++i) {
      const Result& r = f.results[i];
      const int line = i < f.lines.size() ? f.lines[i] : 0;
      out << "    <testcase name=\"" << XmlEscape(r.name + ": " + r.description) << "\" classname=\""
          << classname << "\" file=\"" << XmlEscape(f.file) << "\"";
      if (line > 0) out << " line=\"" << line << "\"";
      out << " time=\"" << Seconds(CaseSeconds(r)) << "\"";
      const std::string when = r.verdict.outcome == Outcome::kPending
                                   ? ""
                                   : " (decided at " + TimeText(r.verdict.time, f.origin) + ")";
      switch (r.verdict.outcome) {
        case Outcome::kPassed:
          out << ">\n      <system-out>" << XmlEscape(r.verdict.detail + when) << "</system-out>\n";
          break;
        case Outcome::kFailed:
          out << ">\n      <failure message=\"" << XmlEscape(r.verdict.detail) << "\" type=\"expectation\">"
              << XmlEscape("expected " + r.description + "\n" + r.verdict.detail + when) << "</failure>\n";
          break;
        default: {
          const std::string why = r.verdict.detail.empty() ? f.error : r.verdict.detail;
          out << ">\n      <skipped message=\"" << XmlEscape(why.empty() ? "not judged" : why) << "\"/>\n";
        }
      }
      out << "    </testcase>\n";
    }
    out << "  </testsuite>\n";
  }
  out << "</testsuites>\n";
}

}  // namespace canfleet::scenario

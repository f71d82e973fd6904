#include "spar/sensing/evidence_json.hpp"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "spar/sensing/error.hpp"
#include "spar/sensing/internal/json_text.hpp"

namespace spar::sensing {
namespace {

using internal::shown;
using nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& path,
                       const std::string& what) {
  throw SensingError(source + ": " + path + ": " + what);
}

Frame read_frame(const json& document, const std::string& source) {
  if (!document.contains("frame")) fail(source, "frame", "missing (a list of hypothesis names)");
  const json& names = document.at("frame");
  if (!names.is_array() || names.empty())
    fail(source, "frame", "expected a non-empty list of names, got " + shown(names));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string path = "frame[" + std::to_string(i) + "]";
    if (!names[i].is_string() || names[i].get<std::string>().empty())
      fail(source, path, "expected a non-empty name, got " + shown(names[i]));
    const std::string name = names[i].get<std::string>();
    if (std::find(out.begin(), out.end(), name) != out.end())
      fail(source, path, "'" + name + "' is listed twice");
    out.push_back(name);
  }
  if (static_cast<int>(out.size()) > kMaxFrameSize)
    fail(source, "frame", "at most " + std::to_string(kMaxFrameSize) + " hypotheses");
  return Frame(std::move(out));
}

FocalSet read_set(const json& value, const Frame& frame, const std::string& source,
                  const std::string& path) {
  if (!value.is_array() || value.empty())
    fail(source, path, "expected a non-empty list of the frame's names, got " + shown(value));
  FocalSet set(frame.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    if (!value[i].is_string()) fail(source, item, "expected a name, got " + shown(value[i]));
    const std::string name = value[i].get<std::string>();
    const auto& names = frame.names();
    const auto found = std::find(names.begin(), names.end(), name);
    if (found == names.end()) fail(source, item, "'" + name + "' is not in the frame");
    set.insert(static_cast<int>(found - names.begin()));
  }
  return set;
}

MassFunction read_source(const json& value, const Frame& frame, const std::string& source,
                         const std::string& path) {
  if (!value.is_array() || value.empty())
    fail(source, path, "expected a non-empty list of {\"set\", \"mass\"}, got " + shown(value));
  std::vector<FocalElement> elements;
  std::set<FocalSet> seen;
  double sum = 0;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    const json& element = value[i];
    if (!element.is_object())
      fail(source, item, "expected {\"set\", \"mass\"}, got " + shown(element));
    for (const auto& [key, unused] : element.items())
      if (key != "set" && key != "mass")
        fail(source, item, "unknown key '" + key + "' (known: set, mass)");
    if (!element.contains("set")) fail(source, item, "missing key 'set'");
    if (!element.contains("mass")) fail(source, item, "missing key 'mass'");
    FocalSet set = read_set(element.at("set"), frame, source, item + ".set");
    const json& mass = element.at("mass");
    if (!mass.is_number() || !(mass.get<double>() >= 0 && mass.get<double>() <= 1))
      fail(source, item + ".mass", "must be a number in [0, 1], got " + shown(mass));
    if (!seen.insert(set).second)
      fail(source, item + ".set", "this set is listed twice in one source");
    sum += mass.get<double>();
    elements.push_back({std::move(set), mass.get<double>()});
  }
  if (!(std::abs(sum - 1) <= 1e-9))
    fail(source, path, "the masses of a source must sum to 1, got " + json(sum).dump());
  return MassFunction::from_elements(frame.size(), std::move(elements));
}

}  // namespace

EvidenceInput evidence_input(const json& document, const std::string& source) {
  if (!document.is_object())
    throw SensingError(source + ": expected an object {\"frame\": [...], \"sources\": [...]}");
  for (const auto& [key, unused] : document.items())
    if (key != "frame" && key != "sources")
      fail(source, key, "unknown key (known: frame, sources)");
  EvidenceInput input{read_frame(document, source), {}};
  if (!document.contains("sources")) fail(source, "sources", "missing (a list of sources)");
  const json& sources = document.at("sources");
  if (!sources.is_array()) fail(source, "sources", "expected a list, got " + shown(sources));
  for (std::size_t i = 0; i < sources.size(); ++i)
    input.sources.push_back(
        read_source(sources[i], input.frame, source, "sources[" + std::to_string(i) + "]"));
  return input;
}

EvidenceInput load_evidence_file(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw SensingError(
        path.string() + ": cannot read the evidence file: " +
        (std::filesystem::exists(path, error) ? "not a regular file" : "no such file"));
  std::ifstream file(path, std::ios::binary);
  if (!file) throw SensingError(path.string() + ": cannot read the evidence file");
  std::ostringstream text;
  text << file.rdbuf();
  return parse_evidence_json(text.str(), path.string());
}

EvidenceInput parse_evidence_json(std::string_view text, const std::string& source) {
  return evidence_input(internal::parse_json_text(text, source), source);
}

nlohmann::ordered_json evidence_json(const Frame& frame, const Combination& result) {
  nlohmann::ordered_json out;
  out["frame"] = frame.names();
  out["masses"] = nlohmann::ordered_json::array();
  for (const FocalElement& element : result.mass.elements())
    out["masses"].push_back({{"set", frame.names_of(element.set)}, {"mass", element.mass}});
  out["conflict"] = result.conflict;
  const std::vector<double> pignistic = result.mass.pignistic();
  nlohmann::ordered_json belief, plausibility, betp;
  for (int x = 0; x < frame.size(); ++x) {
    const FocalSet singleton = FocalSet::of(frame.size(), {x});
    belief[frame.name(x)] = result.mass.belief(singleton);
    plausibility[frame.name(x)] = result.mass.plausibility(singleton);
    betp[frame.name(x)] = pignistic[static_cast<std::size_t>(x)];
  }
  out["belief"] = belief;
  out["plausibility"] = plausibility;
  out["pignistic"] = betp;
  out["ambiguity"] = result.mass.ambiguity();
  out["nonspecificity"] = result.mass.nonspecificity();
  out["ambiguity_measure"] = "pignistic entropy";
  return out;
}

}  // namespace spar::sensing

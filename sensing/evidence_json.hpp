// The JSON forms of `spar evidence` (normative; Python's spar.evidence takes and returns the same):
//
// input   {"frame": [names], "sources": [[{"set": [names], "mass": x}, ...], ...]}
//         Each source is one mass function over the frame: its masses in [0, 1] sum to 1 (within
//         1e-9), every set is a non-empty list of the frame's names, no set is listed twice in a
//         source. No source at all is the vacuous mass (total ignorance).
// output  {"frame": [names], "masses": [{"set": [names], "mass": x}, ...] (the combination's focal
//         elements in FocalSet order), "conflict": K (overall, evidence.hpp), "belief": {name: x},
//         "plausibility": {name: x}, "pignistic": {name: x} (of each singleton), "ambiguity"
//         (entropy of the pignistic probability, bits), "nonspecificity" (bits),
//         "ambiguity_measure": "pignistic entropy"}
//
// Mistakes throw SensingError with the place: "file:line:col: JSON syntax error: ..." for text
// that is not JSON, "file: sources[1][0].mass: must be a number in [0, 1], got \"x\"" for a value.
//
// Example:
//   const EvidenceInput input = parse_evidence_json(R"({"frame": ["a", "b"], "sources": [
//       [{"set": ["a"], "mass": 0.6}, {"set": ["a", "b"], "mass": 0.4}]]})", "inline");
//   const Combination result = combine(input.sources, input.frame.size());
//   std::cout << evidence_json(input.frame, result).dump(2);   // belief {"a": 0.6, "b": 0}
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "spar/sensing/evidence.hpp"

namespace spar::sensing {

struct EvidenceInput {
  Frame frame;
  std::vector<MassFunction> sources;
};

// Reads the file (SensingError: "path: cannot read the evidence file: no such file").
[[nodiscard]] EvidenceInput load_evidence_file(const std::filesystem::path& path);
[[nodiscard]] EvidenceInput parse_evidence_json(std::string_view text, const std::string& source);
[[nodiscard]] EvidenceInput evidence_input(const nlohmann::json& document,
                                           const std::string& source);
[[nodiscard]] nlohmann::ordered_json evidence_json(const Frame& frame, const Combination& result);

}  // namespace spar::sensing

// `spar evidence FILE.json [--json]`: Dempster's combination of the file's sources over its frame
// (sensing/evidence_json.hpp gives both JSON forms): the combined masses, the conflict K, and each
// hypothesis' belief, plausibility and pignistic probability, with the ambiguity (entropy of the
// pignistic probability) and the nonspecificity, in bits.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>
#include <memory>

#include "cli/commands.hpp"
#include "spar/sensing/evidence_json.hpp"

namespace spar::cli {
namespace {

struct EvidenceOptions {
  std::string file;
  bool json{false};
};

std::string braced(const std::vector<std::string>& names) {
  std::string out = "{";
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out + "}";
}

void run(const EvidenceOptions& options) {
  const sensing::EvidenceInput input = sensing::load_evidence_file(options.file);
  const sensing::Combination result = sensing::combine(input.sources, input.frame.size());
  if (options.json) {
    std::cout << sensing::evidence_json(input.frame, result).dump(2) << '\n';
    return;
  }
  std::cout << std::setprecision(6) << input.sources.size() << " source(s) over "
            << input.frame.size() << " hypotheses, conflict K = " << result.conflict
            << "\n\ncombined masses:\n";
  for (const sensing::FocalElement& element : result.mass.elements())
    std::cout << "  " << std::setw(10) << element.mass << "  "
              << braced(input.frame.names_of(element.set)) << '\n';
  std::cout << "\n  hypothesis            belief  plausibility   pignistic\n";
  const std::vector<double> pignistic = result.mass.pignistic();
  for (int x = 0; x < input.frame.size(); ++x) {
    const sensing::FocalSet singleton = sensing::FocalSet::of(input.frame.size(), {x});
    std::cout << "  " << std::left << std::setw(18) << input.frame.name(x) << std::right
              << std::setw(10) << result.mass.belief(singleton) << std::setw(14)
              << result.mass.plausibility(singleton) << std::setw(12)
              << pignistic[static_cast<std::size_t>(x)] << '\n';
  }
  std::cout << "\nambiguity (entropy of the pignistic probability) " << result.mass.ambiguity()
            << " bits, nonspecificity " << result.mass.nonspecificity() << " bits\n";
}

}  // namespace

void add_evidence_command(CLI::App& app) {
  auto options = std::make_shared<EvidenceOptions>();
  CLI::App* command = app.add_subcommand(
      "evidence", "Combine Dempster-Shafer mass functions from a JSON file (Dempster's rule)");
  command
      ->add_option("file", options->file,
                   "JSON: {\"frame\": [names], \"sources\": [[{\"set\": [names], \"mass\": x}]]}")
      ->required();
  command->add_flag("--json", options->json, "print JSON");
  command->callback([options] { run(*options); });
}

}  // namespace spar::cli

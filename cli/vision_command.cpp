// `spar vision`: PSEIKI's verification vision (sensing/pseiki/, survey seed 003 section 4) on a
// scenario's camera (normative forms):
//   spar vision render SCENARIO --camera NAME [--json]
//       the model panel: the expected scene's edges, faces and objects (vision_json.hpp);
//   spar vision match SCENARIO --camera NAME --image FILE.json [--json] [--threshold X]
//                     [--passes 1|2] [--correct OBJECT|camera] [--svg FILE]
//       labels, beliefs, the scene's acceptance and the pose correction;
//   spar vision simulate SCENARIO --camera NAME [--perturb KEY=VALUE[,...]]... [--seed N]
//                        [--output FILE]
//       an image file from the scenario at a perturbed pose. Keys: pose (scale of the pose
//       uncertainty, default 1), noise (pixels, default the camera's noise_px), drop (default
//       1 - detection_probability), split, join, shadow (probabilities, default 0), clutter
//       (edges, default 0), missing=OBJECT, swap=OBJECT:OTHER (repeatable).
#include <CLI/CLI.hpp>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "spar/planner/vision.hpp"
#include "spar/reports/vision_svg.hpp"

namespace spar::cli {
namespace {

namespace pseiki = sensing::pseiki;

struct VisionArguments {
  std::string scenario, camera, image, output, svg, correct;
  std::vector<std::string> perturb;
  std::uint64_t seed{1};
  double threshold{0.5};
  int passes{2};
  bool json{false};
};

void add_common(CLI::App& command, VisionArguments& arguments) {
  command.add_option("scenario", arguments.scenario, "scenario file (YAML, docs/scenario.md)")
      ->required();
  command.add_option("--camera", arguments.camera, "a camera of the scenario's sensors.cameras")
      ->required();
}

void run_render(const VisionArguments& arguments) {
  const planner::Scenario scenario = planner::load_scenario(arguments.scenario);
  const planner::VisionSetup setup(scenario, arguments.camera);
  const pseiki::ModelPanel panel(setup.scene(), setup.camera(), setup.uncertainty());
  if (arguments.json) {
    std::cout << pseiki::render_json(panel, arguments.camera).dump(2) << '\n';
    return;
  }
  std::cout << "expected scene of camera " << arguments.camera << ": " << panel.edges().size()
            << " edges, " << panel.faces().size() << " faces\n\n"
            << std::fixed << std::setprecision(1);
  std::cout << "  edge            p0                p1                tolerance (px)\n";
  for (const pseiki::PanelEdge& edge : panel.edges())
    std::cout << "  " << std::left << std::setw(14) << edge.id << std::right << "  ("
              << std::setw(6) << edge.span.p0.x() << ", " << std::setw(6) << edge.span.p0.y()
              << ")  (" << std::setw(6) << edge.span.p1.x() << ", " << std::setw(6)
              << edge.span.p1.y() << ")  " << edge.tolerance.offset << '\n';
}

int correction_target(const planner::VisionSetup& setup, const std::string& name) {
  if (name.empty()) return pseiki::kAutomaticTarget;
  if (name == "camera") return pseiki::kCameraTarget;
  return setup.object_index(name);
}

void run_match(const VisionArguments& arguments) {
  const planner::Scenario scenario = planner::load_scenario(arguments.scenario);
  const planner::VisionSetup setup(scenario, arguments.camera);
  const pseiki::ImageFile image = pseiki::load_image_file(arguments.image);
  pseiki::MatchOptions options = setup.options();
  options.acceptance = arguments.threshold;
  options.passes = arguments.passes;
  options.target = correction_target(setup, arguments.correct);
  const pseiki::Verification result =
      pseiki::verify(setup.scene(), setup.camera(), setup.uncertainty(), image.edges, options);
  const auto report =
      pseiki::match_json(result, image, arguments.camera, setup.units(), options.acceptance);
  if (!arguments.svg.empty()) {
    const pseiki::ModelPanel believed(setup.scene(), setup.camera(), setup.uncertainty());
    write_file(arguments.svg, "the SVG",
               [&](std::ostream& out) { out << reports::vision_svg(believed, result, image); });
  }
  if (arguments.json) {
    std::cout << report.dump(2) << '\n';
    return;
  }
  std::cout << std::fixed << std::setprecision(2) << "scene belief " << result.board.scene.belief
            << " (threshold " << options.acceptance
            << "): " << (result.accepted ? "accepted" : "rejected") << '\n';
  for (const auto& object : report["objects"])
    std::cout << "  object " << object["label"].get<std::string>() << ": belief "
              << object["belief"].get<double>() << '\n';
  std::cout << "\n  edge        label           belief\n";
  for (const auto& edge : report["edges"])
    std::cout << "  " << std::left << std::setw(10)
              << (edge["id"].is_string() ? edge["id"].get<std::string>() : edge["id"].dump())
              << "  " << std::setw(14)
              << (edge["label"].is_null() ? std::string("-") : edge["label"].get<std::string>())
              << std::right << std::setw(6) << edge["belief"].get<double>() << '\n';
  if (const auto& c = report["pose_correction"]; !c.is_null())
    std::cout << "\npose correction of " << c["object"].get<std::string>() << ": xyz "
              << c["xyz"].dump() << ", dtheta " << c["rpy"][2].get<double>() << ' '
              << report["units"]["angle"].get<std::string>() << ", residual "
              << c["residual"].get<double>() << " px (before " << c["residual_before"].get<double>()
              << " px)\n";
}

// KEY=VALUE pairs of --perturb, comma-separated, into the perturbation and the scene changes.
struct Perturbation {
  pseiki::ImagePerturbation image;
  std::vector<std::string> missing;
  std::vector<planner::VisionSetup::Swap> swaps;
};

Perturbation read_perturbation(const std::vector<std::string>& specs,
                               const planner::CameraSensor& camera) {
  Perturbation out;
  out.image.noise_px = camera.noise_px;
  out.image.drop = 1 - camera.detection_probability;
  const auto probability = [](const std::string& text, const std::string& key) {
    return read_number(text, "--perturb " + key, {0, 1});
  };
  for (const std::string& spec : specs) {
    std::stringstream items(spec);
    std::string item;
    while (std::getline(items, item, ',')) {
      const std::size_t equals = item.find('=');
      if (equals == std::string::npos)
        throw UsageError(
            "--perturb: expected KEY=VALUE, got '" + item +
            "' (keys: pose, noise, drop, split, join, shadow, clutter, missing, swap)");
      const std::string key = item.substr(0, equals), value = item.substr(equals + 1);
      if (key == "pose") {
        out.image.pose_scale = read_number(value, "--perturb pose", NumberLimits::non_negative());
      } else if (key == "noise") {
        out.image.noise_px = read_number(value, "--perturb noise", NumberLimits::non_negative());
      } else if (key == "drop") {
        out.image.drop = probability(value, key);
      } else if (key == "split") {
        out.image.split = probability(value, key);
      } else if (key == "join") {
        out.image.join = probability(value, key);
      } else if (key == "shadow") {
        out.image.shadow = probability(value, key);
      } else if (key == "clutter") {
        out.image.clutter =
            static_cast<int>(read_count(value, "--perturb clutter", 0, pseiki::kMaxClutter));
      } else if (key == "missing") {
        out.missing.push_back(value);
      } else if (key == "swap") {
        const std::size_t colon = value.find(':');
        if (colon == std::string::npos)
          throw UsageError("--perturb swap: expected OBJECT:OTHER, got '" + value + "'");
        out.swaps.push_back({value.substr(0, colon), value.substr(colon + 1)});
      } else {
        throw UsageError(
            "--perturb: unknown key '" + key +
            "' (keys: pose, noise, drop, split, join, shadow, clutter, missing, swap)");
      }
    }
  }
  return out;
}

void run_simulate(const VisionArguments& arguments) {
  const planner::Scenario scenario = planner::load_scenario(arguments.scenario);
  const planner::VisionSetup setup(scenario, arguments.camera);
  const Perturbation perturbation = read_perturbation(arguments.perturb, setup.sensor());
  const planner::VisionSetup::ChangedScene changed =
      setup.changed_scene(perturbation.missing, perturbation.swaps);
  const pseiki::SimulatedImage image = pseiki::simulate(
      changed.scene, setup.camera(), changed.uncertainty, perturbation.image, arguments.seed);
  const std::string text =
      pseiki::simulated_json(image, changed.scene, setup.camera(), arguments.camera, setup.units())
          .dump(2);
  if (arguments.output.empty()) {
    std::cout << text << '\n';
  } else {
    write_file(arguments.output, "the image file", [&](std::ostream& out) { out << text << '\n'; });
  }
}

}  // namespace

void add_vision_command(CLI::App& app) {
  CLI::App* vision = app.add_subcommand(
      "vision", "PSEIKI: match image edges to a camera's expected scene (verification vision)");
  vision->require_subcommand(1);

  auto render = std::make_shared<VisionArguments>();
  CLI::App* render_command =
      vision->add_subcommand("render", "the expected scene (model panel) a camera should see");
  add_common(*render_command, *render);
  render_command->add_flag("--json", render->json, "print JSON");
  render_command->callback([render] { run_render(*render); });

  auto match = std::make_shared<VisionArguments>();
  CLI::App* match_command = vision->add_subcommand(
      "match", "label an image's edges with the expected scene's, accept or reject, correct");
  add_common(*match_command, *match);
  match_command->add_option("--image", match->image, "image file: {\"edges\": [{id, p0, p1}]}")
      ->required();
  match_command->add_flag("--json", match->json, "print JSON");
  add_number_option(*match_command, "--threshold", match->threshold,
                    "scene belief that accepts the interpretation (default 0.5)", {0, 1});
  add_count_option(*match_command, "--passes", match->passes,
                   "1: match once; 2 (default): match again at the corrected pose", 1, 2);
  match_command->add_option("--correct", match->correct,
                            "the pose to correct: an object or 'camera' (default: the camera if "
                            "uncertain, else the most uncertain object)");
  match_command->add_option("--svg", match->svg,
                            "also draw the expected scene and the labelled edges (SVG)");
  match_command->callback([match] { run_match(*match); });

  auto simulate = std::make_shared<VisionArguments>();
  CLI::App* simulate_command =
      vision->add_subcommand("simulate", "an image file of the scenario seen at a perturbed pose");
  add_common(*simulate_command, *simulate);
  simulate_command->add_option(
      "--perturb", simulate->perturb,
      "KEY=VALUE[,...]: pose, noise, drop, split, join, shadow, clutter, missing, swap");
  add_count_option(*simulate_command, "--seed", simulate->seed, "random seed (default 1)", 0,
                   UINT64_MAX);
  simulate_command->add_option("--output", simulate->output, "write the image file here");
  simulate_command->callback([simulate] { run_simulate(*simulate); });
}

}  // namespace spar::cli

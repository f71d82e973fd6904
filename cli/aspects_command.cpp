// `spar aspects OBJECT [--units U] [--max-angle DEG] [--json]`: the aspects of an object
// (sensing/aspects.hpp): each set of faces seen from some view directions, with its solid angle,
// a representative direction and the prominence of the features seen from there. OBJECT is a
// built-in name or an .off / .obj file (coordinates in --units); face numbers are `spar object`'s.
// --level and --resolution set the view sphere's resolution for non-convex objects, and
// --view-sphere uses it for a convex one too.
// --json prints sensing/aspects_json.hpp's form.
#include <CLI/CLI.hpp>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <numbers>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/sensing/aspects.hpp"
#include "spar/sensing/aspects_json.hpp"

namespace spar::cli {
namespace {

struct AspectsOptions {
  std::string object;
  std::string units{"m"};
  double max_angle_degrees{75};
  int level{3};
  int resolution{128};
  bool view_sphere{false};
  bool json{false};
};

void run(const AspectsOptions& options) {
  const double unit = metres_per_unit(options.units);
  const geometry::ObjectModel object = geometry::load_object(options.object, unit);
  sensing::AspectOptions settings;
  settings.max_angle = options.max_angle_degrees * std::numbers::pi / 180;
  settings.view_sphere_level = options.level;
  settings.resolution = options.resolution;
  settings.force_view_sphere = options.view_sphere;
  const sensing::AspectSet aspects = sensing::compute_aspects(object, settings);
  if (options.json) {
    std::cout << sensing::aspects_json(object, aspects, settings, options.units, unit).dump(2)
              << '\n';
    return;
  }
  std::cout << std::setprecision(4) << "object " << object.name() << ": " << aspects.aspects.size()
            << " aspects (" << sensing::to_string(aspects.method);
  if (aspects.method == sensing::AspectMethod::kViewSphere)
    std::cout << ", " << aspects.cells.size() << " view directions, " << options.resolution
              << " samples across";
  std::cout << "), faces seen within " << options.max_angle_degrees << " deg of their normal\n\n"
            << "  label  solid angle (sr)  direction                      faces\n";
  for (const sensing::Aspect& aspect : aspects.aspects) {
    const auto clean = [](double x) { return std::abs(x) < 5e-4 ? 0.0 : x; };  // no "-0.000"
    std::ostringstream direction;
    direction << std::fixed << std::setprecision(3) << '(' << clean(aspect.direction.x()) << ", "
              << clean(aspect.direction.y()) << ", " << clean(aspect.direction.z()) << ')';
    std::cout << "  " << std::left << std::setw(6) << aspect.label << std::right << std::setw(13)
              << aspect.solid_angle << "      " << std::left << std::setw(31) << direction.str()
              << std::right;
    for (const int face : aspect.faces) std::cout << ' ' << face;
    std::cout << '\n';
  }
}

}  // namespace

void add_aspects_command(CLI::App& app) {
  auto options = std::make_shared<AspectsOptions>();
  CLI::App* command = app.add_subcommand(
      "aspects", "Group an object's view directions by the faces they see (aspects)");
  command->add_option("object", options->object, "an .off/.obj file, or peg, block, cube, l-shape")
      ->required();
  command
      ->add_option("--units", options->units, "length unit of FILE and of the output (default m)")
      ->check(CLI::IsMember({"m", "mm", "in"}));
  add_number_option(*command, "--max-angle", options->max_angle_degrees,
                    "a face is seen within this angle of its normal, degrees in (0, 90]",
                    {0, 90, true});
  add_count_option(
      *command, "--level", options->level,
      "view-sphere subdivisions for non-convex objects (20 * 4^level directions), 0 to 6", 0, 6);
  add_count_option(*command, "--resolution", options->resolution,
                   "item-buffer samples across the object per view direction, 16 to 1024", 16,
                   1024);
  command->add_flag("--view-sphere", options->view_sphere,
                    "use the view sphere even for a convex object");
  command->add_flag("--json", options->json, "print JSON");
  command->callback([options] { run(*options); });
}

}  // namespace spar::cli

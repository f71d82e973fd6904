// spar._spar: pybind11 bindings of the facade (python/facade.hpp). Only type conversion lives
// here: 4x4 poses and joint vectors as NumPy arrays, box and witnesses as dicts, reports as
// dict/list, spar's exceptions as the spar.Error hierarchy with the same messages. Scenario
// loading, planning, instance analysis, bounding, Expr's methods and UncertainPose's entry and
// evaluate release the GIL (the facade's pool mutex serialises work on one pool), so a thread that
// waits for a pool or a long computation never holds up the other Python threads. The package's
// Python part (python/spar/__init__.py) wraps these in the public names.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <numbers>
#include <optional>

#include "python/docstrings.hpp"
#include "python/facade.hpp"
#include "spar/bounds/error.hpp"
#include "spar/bounds/shostak.hpp"
#include "spar/common/number.hpp"
#include "spar/geometry/error.hpp"
#include "spar/kinematics/error.hpp"
#include "spar/planner/cms/error.hpp"
#include "spar/planner/error.hpp"
#include "spar/qr/error.hpp"
#include "spar/reports/error.hpp"
#include "spar/sensing/error.hpp"
#include "spar/symbolic/error.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace spar::python {
namespace {

using Release = py::call_guard<py::gil_scoped_release>;

// JSON -> dict / list / str / int / float / bool / None, keys in the document's order.
py::object to_python(const nlohmann::ordered_json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::object: {
      py::dict out;
      for (const auto& [key, item] : value.items()) out[py::str(key)] = to_python(item);
      return out;
    }
    case nlohmann::json::value_t::array: {
      py::list out;
      for (const auto& item : value) out.append(to_python(item));
      return out;
    }
    case nlohmann::json::value_t::string:
      return py::str(value.get_ref<const std::string&>());
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.get<bool>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.get<std::uint64_t>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.get<std::int64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.get<double>());
    default:
      return py::none();
  }
}

template <typename CppError>
py::handle add_error(py::module_& m, const char* name, py::handle base) {
  return py::register_exception<CppError>(m, name, base);
}

// The spar.Error hierarchy. pybind11 tries translators newest first, so a subclass is
// registered after its base (ShostakError after BoundsError, the module errors after Error).
void register_errors(py::module_& m) {
  const py::handle error = add_error<spar::Error>(m, "Error", PyExc_Exception);
  error.attr("__doc__") = doc::of("Error");
  const py::handle bounds = add_error<bounds::BoundsError>(m, "BoundsError", error);
  add_error<bounds::ShostakError>(m, "ShostakError", bounds);
  add_error<NumberError>(m, "NumberError", error);
  add_error<symbolic::SymbolicError>(m, "SymbolicError", error);
  add_error<kinematics::KinematicsError>(m, "KinematicsError", error);
  add_error<geometry::GeometryError>(m, "GeometryError", error);
  add_error<planner::cms::CmsError>(m, "CmsError", error);
  add_error<planner::ScenarioError>(m, "ScenarioError", error);
  add_error<planner::DomainError>(m, "DomainError", error);
  add_error<planner::PlanError>(m, "PlanError", error);
  add_error<qr::QrError>(m, "QrError", error);
  add_error<reports::ReportError>(m, "ReportError", error);
  add_error<sensing::SensingError>(m, "SensingError", error);
}

kinematics::PoseUncertainty uncertainty_from(const std::map<std::string, double>& values) {
  kinematics::PoseUncertainty out;
  for (const auto& [key, value] : values) {
    if (key == "dx")
      out.dx = value;
    else if (key == "dy")
      out.dy = value;
    else if (key == "dz")
      out.dz = value;
    else if (key == "dtheta")
      out.dtheta = value;
    else
      throw py::value_error("unknown uncertainty '" + key +
                            "': the half-widths are dx, dy, dz (m) and dtheta (rad)");
  }
  return out;
}

// A bound record's member as Python: numbers as floats (inf and nan included), witnesses as
// dicts in the box's order.
template <class T>
py::object member_to_python(const T& value) {
  return py::cast(value);
}
py::object member_to_python(const reports::Nullable<double>& value) {
  if (!value) return py::none();
  return py::float_(*value);
}
py::object member_to_python(const reports::NamedValues<double>& values) {
  py::dict out;
  for (const auto& [name, value] : values) out[py::str(name)] = value;
  return out;
}
template <class T>
void member_from_python(const py::handle& value, T& out) {
  out = value.cast<T>();
}
void member_from_python(const py::handle& value, reports::Nullable<double>& out) {
  out = value.is_none() ? reports::Nullable<double>()
                        : reports::Nullable<double>(value.cast<double>());
}
void member_from_python(const py::handle& value, reports::NamedValues<double>& out) {
  out.clear();
  for (const auto& [name, number] : value.cast<py::dict>())
    out.emplace_back(name.cast<std::string>(), number.cast<double>());
}

// The bound record as a dict with the keys of `spar bound --json` (name only when it has one).
py::dict bound_dict(const reports::BoundRecord& r) {
  py::dict out;
  reports::BoundRecord::fields(r, [&]<class M>(const char* key, const M& member) {
    if constexpr (std::is_same_v<M, std::optional<std::string>>) {
      if (member) out[key] = *member;
    } else {
      out[key] = member_to_python(member);
    }
  });
  return out;
}

reports::BoundRecord bound_from_dict(const py::dict& d) {
  reports::BoundRecord r;
  reports::BoundRecord::fields(r, [&]<class M>(const char* key, M& member) {
    if (d.contains(key)) member_from_python(d[key], member);
  });
  return r;
}

// BoundResult's attributes: one read-only property per member of the bound record.
void bind_bound_record(py::class_<reports::BoundRecord>& cls) {
  const reports::BoundRecord names;
  reports::BoundRecord::fields(names, [&](const char* key, const auto&) {
    cls.def_property_readonly(
        key,
        [key](const reports::BoundRecord& r) {
          py::object out = py::none();
          reports::BoundRecord::fields(r, [&]<class M>(const char* name, const M& member) {
            if (std::string_view(name) != key) return;
            if constexpr (std::is_same_v<M, std::optional<std::string>>) {
              if (member) out = py::str(*member);
            } else {
              out = member_to_python(member);
            }
          });
          return out;
        },
        doc::of(std::string("BoundResult.") + key));
  });
}

void bind_expressions(py::module_& m) {
  py::class_<Expression>(m, "Expr", doc::of("Expr"))
      .def(py::init(&parse_expression), "text"_a, doc::of("Expr.__init__"))
      .def_static("parse", &parse_expression, "text"_a, doc::of("Expr.parse"))
      .def("__str__", &expression_text, Release())
      .def("__repr__",
           [](const Expression& e) { return "spar.Expr('" + expression_text(e) + "')"; })
      .def("simplify", &simplify_expression, Release(), doc::of("Expr.simplify"))
      .def("diff", &differentiate_expression, "variable"_a, Release(), doc::of("Expr.diff"))
      .def("evaluate", &evaluate_expression, "values"_a, Release(), doc::of("Expr.evaluate"))
      .def_property_readonly("variables", &expression_variables, doc::of("Expr.variables"))
      // Not hashable (pybind11 sets __hash__ = None with __eq__): equal expressions of two
      // pools may print differently (see facade.hpp).
      .def("__eq__", &same_expression, Release())
      .def(py::pickle([](const Expression& e) { return expression_text(e); },
                      [](const std::string& text) { return parse_expression(text); }));

  py::class_<reports::BoundRecord> bound_result(m, "BoundResult", doc::of("BoundResult"));
  bind_bound_record(bound_result);
  bound_result.def("as_dict", &bound_dict, doc::of("BoundResult.as_dict"))
      .def("__repr__",
           [](const reports::BoundRecord& r) {
             return "spar.BoundResult(lo=" + py::repr(py::float_(r.lo)).cast<std::string>() +
                    ", hi=" + py::repr(py::float_(r.hi)).cast<std::string>() + ", status='" +
                    r.status + "')";
           })
      .def(py::pickle([](const reports::BoundRecord& r) { return bound_dict(r); },
                      &bound_from_dict));

  py::class_<ConstraintSpec>(m, "_Constraint")
      .def(py::init([](const Expression& g, const std::string& relation) {
             return ConstraintSpec{g, relation, ""};
           }),
           "g"_a, "relation"_a)
      .def(py::init([](const std::string& text) {
             return ConstraintSpec{std::nullopt, "", text};
           }),
           "text"_a);

  m.def(
      "_bound",
      [](const Expression& f, const std::vector<std::tuple<std::string, double, double>>& box,
         const std::vector<ConstraintSpec>& constraints, double tolerance,
         std::size_t max_box_evaluations, double max_seconds, bool inner) {
        std::vector<BoxRange> ranges;
        for (const auto& [name, lo, hi] : box) ranges.push_back({name, lo, hi});
        return bound_expression(f, ranges, constraints,
                                {tolerance, max_box_evaluations, max_seconds, inner});
      },
      "f"_a, "box"_a, "constraints"_a, "tolerance"_a, "max_box_evaluations"_a, "max_seconds"_a,
      "inner"_a, Release());
}

// A robot's package search path from Python's optional list of folders.
std::vector<std::string> package_path(const std::optional<std::vector<std::string>>& folders) {
  return folders.value_or(std::vector<std::string>{});
}

// robots(), robot() and fk().
void bind_robots(py::module_& m) {
  m.def("robots", &robot_names, doc::of("robots"));
  m.def(
      "robot",
      [](const std::string& robot, const std::string& tip,
         const std::optional<std::vector<std::string>>& folders) {
        const RobotInfo info = robot_info({robot, tip, package_path(folders)});
        py::list joints;
        for (const JointInfo& j : info.joints) {
          py::dict joint("name"_a = j.name, "type"_a = j.type, "lower"_a = j.lower,
                         "upper"_a = j.upper);
          if (j.dh) {
            joint["d"] = (*j.dh)[0];
            joint["a"] = (*j.dh)[1];
            joint["alpha"] = (*j.dh)[2];
            joint["offset"] = (*j.dh)[3];
          }
          joints.append(joint);
        }
        return py::dict("name"_a = info.name, "source"_a = info.source, "base"_a = info.base,
                        "tip"_a = info.tip, "method"_a = info.method, "joints"_a = joints);
      },
      "robot"_a, "tip"_a = "", "package_path"_a = py::none(), doc::of("robot"));
  m.def(
      "fk",
      [](const std::string& robot, const std::vector<double>& q, const std::string& tip,
         const std::optional<std::vector<std::string>>& folders) {
        return forward_kinematics({robot, tip, package_path(folders)}, q);
      },
      "robot"_a, "q"_a, "tip"_a = "", "package_path"_a = py::none(), doc::of("fk"));
}

// IkSolution, IkResult and ik().
void bind_ik(py::module_& m) {
  py::class_<IkSolutionInfo>(m, "IkSolution", doc::of("IkSolution"))
      .def_readonly("configuration", &IkSolutionInfo::configuration,
                    doc::of("IkSolution.configuration"))
      .def_property_readonly(
          "q",
          [](const IkSolutionInfo& s) {
            return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                s.q.data(), static_cast<Eigen::Index>(s.q.size())));
          },
          doc::of("IkSolution.q"))
      .def_readonly("within_limits", &IkSolutionInfo::within_limits,
                    doc::of("IkSolution.within_limits"))
      .def_readonly("singularities", &IkSolutionInfo::singularities,
                    doc::of("IkSolution.singularities"))
      .def("__repr__", [](const IkSolutionInfo& s) {
        return "spar.IkSolution('" + s.configuration +
               "', within_limits=" + (s.within_limits ? "True" : "False") + ")";
      });
  py::class_<IkAnswer>(m, "IkResult", doc::of("IkResult"))
      .def_readonly("solved", &IkAnswer::solved, doc::of("IkResult.solved"))
      .def_readonly("singularities", &IkAnswer::singularities, doc::of("IkResult.singularities"))
      .def_readonly("solutions", &IkAnswer::solutions, doc::of("IkResult.solutions"))
      .def("__len__", [](const IkAnswer& r) { return r.solutions.size(); })
      .def(
          "__getitem__",
          [](const IkAnswer& r, const std::string& configuration) {
            for (const IkSolutionInfo& s : r.solutions)
              if (s.configuration == configuration) return s;
            throw py::key_error("no solution '" + configuration + "'");
          },
          "configuration"_a, doc::of("IkResult.__getitem__"));
  m.def(
      "ik",
      [](const std::string& robot, const Matrix4& pose, const std::string& tip,
         const std::optional<std::vector<std::string>>& folders, double redundancy_step) {
        return inverse_kinematics({robot, tip, package_path(folders)}, pose, redundancy_step);
      },
      "robot"_a, "pose"_a, "tip"_a = "", "package_path"_a = py::none(),
      "redundancy_step"_a = 5.0 * std::numbers::pi / 180.0, Release(), doc::of("ik"));
}

// UncertainPose and the possible object and manipulator poses (SPAR's eq. 1).
void bind_uncertain_poses(py::module_& m) {
  py::class_<UncertainPose>(m, "UncertainPose", doc::of("UncertainPose"))
      .def("entry", &pose_entry, "row"_a, "column"_a, Release(), doc::of("UncertainPose.entry"))
      .def(
          "__getitem__",
          [](const UncertainPose& pose, std::pair<int, int> index) {
            return pose_entry(pose, index.first, index.second);
          },
          "index"_a)
      .def_property_readonly(
          "matrix",
          [](const UncertainPose& pose) {
            std::vector<std::vector<Expression>> rows(4);
            for (int r = 0; r < 4; ++r)
              for (int c = 0; c < 4; ++c) rows[r].push_back(pose_entry(pose, r, c));
            return rows;
          },
          doc::of("UncertainPose.matrix"))
      .def_property_readonly(
          "variables",
          [](const UncertainPose& pose) {
            py::dict out;
            for (const auto& v : pose.variables)
              out[py::str(v.name)] = py::make_tuple(v.lower, v.upper);
            return out;
          },
          doc::of("UncertainPose.variables"))
      .def("evaluate", &evaluate_pose, "values"_a, Release(), doc::of("UncertainPose.evaluate"));
  m.def(
      "possible_object_pose",
      [](const Matrix4& ideal, const std::map<std::string, double>& uncertainty,
         const std::string& tag) {
        return possible_object_pose(ideal, uncertainty_from(uncertainty), tag);
      },
      "ideal"_a, "uncertainty"_a, "tag"_a = "o", doc::of("possible_object_pose"));
  m.def(
      "possible_manipulator_pose",
      [](const Matrix4& ideal, const std::map<std::string, double>& uncertainty,
         const std::string& tag) {
        return possible_manipulator_pose(ideal, uncertainty_from(uncertainty), tag);
      },
      "ideal"_a, "uncertainty"_a, "tag"_a = "g", doc::of("possible_manipulator_pose"));
}

void bind_kinematics(py::module_& m) {
  bind_robots(m);
  bind_ik(m);
  bind_uncertain_poses(m);
}

void bind_planner(py::module_& m) {
  py::class_<planner::Scenario>(m, "Scenario", doc::of("Scenario"))
      .def_readonly("name", &planner::Scenario::name, doc::of("Scenario.name"))
      .def_readonly("description", &planner::Scenario::description, doc::of("Scenario.description"))
      .def_property_readonly("meshes", &scenario_mesh_files, doc::of("Scenario.meshes"))
      .def_readonly("warnings", &planner::Scenario::warnings, doc::of("Scenario.warnings"));
  m.def("_load_scenario", &load_scenario_file, "path"_a, Release());
  m.def("_read_scenario_text", &read_scenario_file_text, "path"_a, Release());
  m.def("_read_domain_text", &read_domain_file_text, "path"_a, Release());
  m.def(
      "_read_mesh_bytes",
      [](const std::string& path) {
        std::string bytes;
        {
          const py::gil_scoped_release release;
          bytes = read_mesh_file_bytes(path);
        }
        return py::bytes(bytes);
      },
      "path"_a);
  m.def("_parse_scenario", &parse_scenario_text, "text"_a, "source"_a, "base_dir"_a, Release());

  py::class_<PlanRun>(m, "PlanRun", doc::of("PlanRun"))
      .def_property_readonly(
          "report", [](const PlanRun& run) { return to_python(run.report); },
          doc::of("PlanRun.report"))
      .def_property_readonly("instance_count", &instance_count, doc::of("PlanRun.instance_count"))
      .def(
          "analyse",
          [](const PlanRun& run, std::size_t index, bool extras) {
            nlohmann::ordered_json analysis;
            {
              const py::gil_scoped_release release;
              analysis = analyse_instance_json(run, index, extras);
            }
            return to_python(analysis);
          },
          "index"_a, "extras"_a = false, doc::of("PlanRun.analyse"));
  py::class_<PlanSettings>(m, "_PlanSettings")
      .def(py::init<>())
      .def_readwrite("instances", &PlanSettings::instances)
      .def_readwrite("max_nodes", &PlanSettings::max_nodes)
      .def_readwrite("max_steps", &PlanSettings::max_steps)
      .def_readwrite("domain_path", &PlanSettings::domain_path)
      .def_readwrite("domain_text", &PlanSettings::domain_text)
      .def_readwrite("domain_source", &PlanSettings::domain_source)
      .def_readwrite("probability", &PlanSettings::probability)
      .def_readwrite("chosen_extras", &PlanSettings::chosen_extras)
      .def_readwrite("threads", &PlanSettings::threads);
  m.def("_plan_run", &plan_scenario, "scenario"_a, "settings"_a, Release());
  m.def(
      "_plan",
      [](const planner::Scenario& scenario, const PlanSettings& settings) {
        nlohmann::ordered_json report;
        {
          const py::gil_scoped_release release;
          report = plan_scenario(scenario, settings).report;
        }
        return to_python(report);
      },
      "scenario"_a, "settings"_a);
}

void bind_sensing(py::module_& m) {
  m.def(
      "_evidence_text",
      [](const std::string& text, const std::string& source) {
        return to_python(evidence_text_json(text, source));
      },
      "text"_a, "source"_a);
  m.def(
      "_evidence_file",
      [](const std::filesystem::path& path) { return to_python(evidence_file_json(path)); },
      "path"_a);
  py::class_<AspectSettings>(m, "_AspectSettings")
      .def(py::init<>())
      .def_readwrite("units", &AspectSettings::units)
      .def_readwrite("metres_per_unit", &AspectSettings::metres_per_unit)
      .def_readwrite("max_angle_degrees", &AspectSettings::max_angle_degrees)
      .def_readwrite("level", &AspectSettings::level)
      .def_readwrite("resolution", &AspectSettings::resolution)
      .def_readwrite("view_sphere", &AspectSettings::view_sphere);
  m.def(
      "_aspects",
      [](const std::string& object, const AspectSettings& settings) {
        nlohmann::ordered_json out;
        {
          const py::gil_scoped_release release;
          out = object_aspects_json(object, settings);
        }
        return to_python(out);
      },
      "object"_a, "settings"_a);
  m.def(
      "_sense_plan",
      [](const planner::Scenario& scenario) {
        nlohmann::ordered_json out;
        {
          const py::gil_scoped_release release;
          out = sense_plan_json(scenario);
        }
        return to_python(out);
      },
      "scenario"_a);
}

}  // namespace
}  // namespace spar::python

PYBIND11_MODULE(_spar, m) {
  m.doc() = spar::python::doc::of("");
  m.attr("__version__") = SPAR_VERSION;
  spar::python::register_errors(m);
  spar::python::bind_expressions(m);
  spar::python::bind_kinematics(m);
  spar::python::bind_planner(m);
  spar::python::bind_sensing(m);
}

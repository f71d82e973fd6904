// The report model: the report of a planning run as plain typed records, built once from the
// planner's result (reports/build.hpp) and written by thin back ends: JSON, the source of truth
// (reports/json.hpp, schema "spar-report/1", docs/report-schema.md field by field), Markdown
// (reports/markdown.hpp) and HTML (reports/html.hpp). The CLI and the Python module use these
// records too: `spar plan --json`, `spar.plan()` and `PlanRun.analyse()` give the same keys, and
// `spar bound --json`/`--jsonl` and `spar.bound()` share one BoundRecord.
//
// Each record lists its JSON members once, in `fields`: `field("key", self.member)` in the order
// they appear in the JSON. The JSON writer and reader are generated from these lists, so:
//   * To add a field to a step (or a precondition, or any record): add the member to the record
//     and its `field(...)` line to the record's `fields` (its place there is its place in the
//     JSON); set it in reports/build.cpp; document it in docs/report-schema.md (a row of the
//     field table and the member in the JSON Schema: tests/reports/schema_test.cpp checks both
//     ways, and that some example produces it). Nothing else: writing and reading it back follow.
//   * A member's type says how it is written:
//       double              a JSON number, or "inf", "-inf", "nan" (JSON has neither)
//       int, size_t, bool,
//       std::string         as themselves
//       std::vector<T>      an array; std::array<T, N>: an array of N
//       NamedValues<T>      an object whose keys are names (variables), in this order
//       std::optional<T>    the member is absent when empty (present-or-absent fields)
//       Nullable<T>         the member is null when empty (always-present fields)
//       a record            an object of its own fields
//   * Reading a document back (report_from_json) refuses a missing member that is not optional,
//     naming its path; members it does not know are ignored (a newer report of the same schema
//     renders with what this version knows).
//
// Units (as the JSON says them): poses, widths, finger openings, `display` values in the
// scenario's length and angle units; precondition expressions, their bounds, witnesses and boxes
// in SI (metres, radians), so that an expression can be bounded again by `spar bound`.
//
// Numbering: a chosen step is named by its execution position, "#k action object" (k from 1,
// inserted steps included), everywhere a report names it; step_label() gives it.
//
// Example:
//   const Report report = build_report(planner::plan(scenario, planner::builtin_domain()));
//   std::cout << to_json(report).dump(2);              // what `spar plan --json` prints
//   if (report.chosen) std::cout << step_label(*report.chosen, 0);   // "#1 pickup block"
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace spar::reports {

// The version of the report's layout; a reader checks it before anything else.
inline constexpr const char* kReportSchema = "spar-report/1";

// A 4x4 homogeneous transform, row-major, its translation in the report's length unit.
using Matrix = std::array<std::array<double, 4>, 4>;
// Values keyed by name (uncertainty variables), written as one JSON object in this order.
template <class T>
using NamedValues = std::vector<std::pair<std::string, T>>;

// An always-present member that may be null: "object": null for a step without one.
template <class T>
struct Nullable : std::optional<T> {
  using std::optional<T>::optional;
};

struct Units {
  std::string length;  // m | mm | in
  std::string angle;   // rad | deg
  double metres_per_length{1.0};
  double radians_per_angle{1.0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("length", s.length);
    field("angle", s.angle);
    field("metres_per_length", s.metres_per_length);
    field("radians_per_angle", s.radians_per_angle);
  }
};

struct Robot {
  std::string model;
  std::optional<std::string> urdf;  // model "urdf": the file as the scenario names it
  // URDF-based robots (ur5, panda, urdf): the chain's ends, and the joints `joints` lists.
  std::optional<std::string> base_link;
  std::optional<std::string> tip;
  std::optional<std::vector<std::string>> joint_names;
  Matrix base{};
  Matrix tool{};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("model", s.model);
    field("urdf", s.urdf);
    field("base_link", s.base_link);
    field("tip", s.tip);
    field("joint_names", s.joint_names);
    field("base", s.base);
    field("tool", s.tool);
  }
};

// ---- phase 1: the plan family ----

struct FamilyStep {
  int id{0};                     // 0 the initial state, 1 the finish
  std::string action;            // template name, or start / finish
  Nullable<std::string> effect;  // the domain's effect (docs/domain.md); null for start / finish
  std::vector<std::string> args;
  std::string text;  // "pickup(peg, grasp_1, initial_peg)"
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("id", s.id);
    field("action", s.action);
    field("effect", s.effect);
    field("args", s.args);
    field("text", s.text);
  }
};

struct PlanVariable {
  std::string name;  // grasp_1, pos_1
  std::string type;  // object | grasp | position | placement
  std::string object;
  std::vector<std::string> labels;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("type", s.type);
    field("object", s.object);
    field("labels", s.labels);
  }
};

struct Arc {
  std::array<std::string, 2> variables;
  std::vector<std::array<std::string, 2>> pairs;  // allowed label pairs
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("variables", s.variables);
    field("pairs", s.pairs);
  }
};

struct SatisfiedGoal {
  std::string level;  // operational | geometric
  std::string condition;
  int step{0};
  std::string how;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("level", s.level);
    field("condition", s.condition);
    field("step", s.step);
    field("how", s.how);
  }
};

struct SearchEffort {
  std::size_t expanded{0};
  std::size_t generated{0};
  double seconds{0.0};  // wall clock: varies run to run
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("expanded", s.expanded);
    field("generated", s.generated);
    field("seconds", s.seconds);
  }
};

struct Family {
  std::vector<FamilyStep> steps;
  std::vector<std::array<int, 2>> ordering;  // prior_to, transitive reduction: ids
  std::vector<PlanVariable> variables;
  std::vector<Arc> arcs;
  std::vector<SatisfiedGoal> goals;
  SearchEffort search;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("steps", s.steps);
    field("ordering", s.ordering);
    field("variables", s.variables);
    field("arcs", s.arcs);
    field("goals", s.goals);
    field("search", s.search);
  }
};

// ---- plan instances ----

struct ExaminedInstance {
  std::size_t index{0};  // 0-based
  int errors{0};
  std::size_t steps{0};
  std::size_t inserted{0};
  std::size_t preconditions{0};
  std::size_t failed_preconditions{0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("index", s.index);
    field("errors", s.errors);
    field("steps", s.steps);
    field("inserted", s.inserted);
    field("preconditions", s.preconditions);
    field("failed_preconditions", s.failed_preconditions);
  }
};

struct Instances {
  std::size_t count{0};
  bool limit_reached{false};
  std::vector<ExaminedInstance> examined;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("count", s.count);
    field("limit_reached", s.limit_reached);
    field("examined", s.examined);
  }
};

// ---- the chosen instance: steps and their preconditions ----

struct Grasp {
  std::string label;  // G5
  std::array<int, 2> faces{};
  double width{0.0};  // length unit
  Matrix gripper_in_object{};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("label", s.label);
    field("faces", s.faces);
    field("width", s.width);
    field("gripper_in_object", s.gripper_in_object);
  }
};

// A precondition's bounds in the scenario's units, for reading.
struct DisplayBounds {
  std::string unit;  // the length unit, or "1" (dimensionless)
  double threshold{0.0}, lo{0.0}, hi{0.0};
  Nullable<double> inner_lo{}, inner_hi{};  // null as the precondition's
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("unit", s.unit);
    field("threshold", s.threshold);
    field("lo", s.lo);
    field("hi", s.hi);
    field("inner_lo", s.inner_lo);
    field("inner_hi", s.inner_hi);
  }
};

struct Blame {
  std::string variable;
  double share{0.0};  // of the bound's width
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("variable", s.variable);
    field("share", s.share);
  }
};

// The reverse-analysis scale as half-widths (scenario units).
struct Margin {
  double displacement{0.0};
  double rotation{0.0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("displacement", s.displacement);
    field("rotation", s.rotation);
  }
};

// One uncertainty precondition of a step: expression relation threshold, decided over its box.
struct Precondition {
  std::string name;      // SPAR's, e.g. "0 < [0,1,0,0] P1^-1 C1"
  std::string kind;      // pickup | squeeze | assemble
  std::string relation;  // < <= > >=
  double threshold{0.0};
  std::string unit;  // SI unit of the expression: m, or 1 (a cosine)
  std::string expression;
  std::size_t nodes{0};
  double lo{0.0}, hi{0.0};  // SI
  // Attained at the witnesses (SI); null when no attained range is known (no_inner_range says
  // why: no witness, or witness values enclosed too loosely), never a swapped [hi, lo].
  Nullable<double> inner_lo, inner_hi;
  std::optional<std::string> no_inner_range;
  std::string verdict;                     // satisfied | violated | undecided
  NamedValues<double> witness;             // the worst point found (SI)
  NamedValues<std::array<double, 2>> box;  // the ranges the bound holds over
  DisplayBounds display;
  // The chosen instance's extras (absent elsewhere):
  std::optional<std::vector<Blame>> blame;         // largest share first
  std::optional<double> holds_up_to_scale;         // reverse analysis: proved up to this scale
  std::optional<bool> holds_up_to_capped;          // the scale is the search's cap: it holds beyond
  std::optional<Margin> margin;                    // with holds_up_to_scale
  std::optional<double> monte_carlo_violation;     // share of uniform samples violating it
  std::optional<std::size_t> monte_carlo_samples;  // behind it (fewer when proved)
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("kind", s.kind);
    field("relation", s.relation);
    field("threshold", s.threshold);
    field("unit", s.unit);
    field("expression", s.expression);
    field("nodes", s.nodes);
    field("lo", s.lo);
    field("hi", s.hi);
    field("inner_lo", s.inner_lo);
    field("inner_hi", s.inner_hi);
    field("no_inner_range", s.no_inner_range);
    field("verdict", s.verdict);
    field("witness", s.witness);
    field("box", s.box);
    field("display", s.display);
    field("blame", s.blame);
    field("holds_up_to_scale", s.holds_up_to_scale);
    field("holds_up_to_capped", s.holds_up_to_capped);
    field("margin", s.margin);
    field("monte_carlo_violation", s.monte_carlo_violation);
    field("monte_carlo_samples", s.monte_carlo_samples);
  }
};

// A failed step: the range-scan residual (scenario units) that would make it hold.
struct SensorResidual {
  double scale{0.0};   // times the scenario's residual
  bool capped{false};  // the scale is the search's cap: a residual this much coarser would do
  double dx{0.0}, dy{0.0}, dz{0.0}, dtheta{0.0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("scale", s.scale);
    field("capped", s.capped);
    field("dx", s.dx);
    field("dy", s.dy);
    field("dz", s.dz);
    field("dtheta", s.dtheta);
  }
};

struct Outcome {
  std::string when, error, recovery;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("when", s.when);
    field("error", s.error);
    field("recovery", s.recovery);
  }
};

// One visible edge of the expected scene, in the camera's pixels (u right, v down).
struct VisionViewEdge {
  std::string id, object;                     // "peg/e3", "peg"
  std::vector<std::array<double, 4>> pieces;  // visible pieces, [u0, v0, u1, v1]
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("id", s.id);
    field("object", s.object);
    field("pieces", s.pieces);
  }
};

// The expected scene as the camera renders it (the model panel), for the reports' drawing.
struct VisionView {
  int width{0}, height{0};  // the image, pixels
  std::vector<VisionViewEdge> edges;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("width", s.width);
    field("height", s.height);
    field("edges", s.edges);
  }
};

// What PSEIKI must see to accept (planner/vision.hpp's VisionCheck).
struct VisionCheck {
  std::string camera, object;
  std::vector<std::string> edges;  // model edges expected visible, "peg/e3"
  double acceptance{0.0};          // scene belief that accepts
  std::optional<VisionView> view;  // absent in reports of earlier versions
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("camera", s.camera);
    field("object", s.object);
    field("edges", s.edges);
    field("acceptance", s.acceptance);
    field("view", s.view);
  }
};

struct Verification {
  std::string name, sense, expect;
  std::vector<Outcome> outcomes;
  std::optional<VisionCheck> vision;  // scenarios with cameras that see the object
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("sense", s.sense);
    field("expect", s.expect);
    field("outcomes", s.outcomes);
    field("vision", s.vision);
  }
};

struct Recovery {
  std::string error, plan;
  std::vector<std::string> steps;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("error", s.error);
    field("plan", s.plan);
    field("steps", s.steps);
  }
};

// How close a step's robot comes to the other objects (issue 21): at the step's configuration,
// the distance in metres (whatever the scenario's unit; inf when there is no other object) from
// the gripper and what it moves to the nearest other object, and that object.
struct Clearance {
  double min_distance{0.0};
  Nullable<std::string> to;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("min_distance", s.min_distance);
    field("to", s.to);
  }
};

// One step of the chosen instance, in execution order. The presence of a member follows the
// step's kind: a grasp for manipulations, poses where the step has a position, the fixed object
// for assemblies, phase 2's results when phase 2 ran.
// A precondition of a chosen step: index into Chosen::steps and into its preconditions.
struct PreconditionRef {
  std::size_t step{0};
  int index{0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("step", s.step);
    field("index", s.index);
  }
};

// A sensing step's operation (`steps[].sensing`, normative), chosen by minimax ambiguity.
struct SensingChoice {
  std::string sensor;
  std::string viewpoint;                // a fixed sensor's name, or V1, V2, ... of a wrist sensor
  std::string aspect;                   // the aspect the object shows it under the first hypothesis
  double predicted_max_ambiguity{0.0};  // bits
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("sensor", s.sensor);
    field("viewpoint", s.viewpoint);
    field("aspect", s.aspect);
    field("predicted_max_ambiguity", s.predicted_max_ambiguity);
  }
};

struct Step {
  int id{0};  // the family step's id; steps phase 2 inserted get new ids
  std::string action;
  std::string effect;  // the domain's effect: grasp | release | insert | sense | reduce | none
  Nullable<std::string> object;
  std::optional<Grasp> grasp;
  std::optional<Matrix> object_pose;                    // where the step finds or leaves it
  std::optional<Nullable<std::string>> stable_pose;     // with object_pose
  std::optional<Matrix> gripper_pose;                   // with grasp
  std::optional<Nullable<std::vector<double>>> joints;  // with grasp; null: unreachable (rad)
  std::optional<Nullable<std::string>> configuration;   // with grasp
  std::optional<std::string> fixed_object;              // assemblies
  std::optional<Matrix> fixed_pose;
  std::optional<Matrix> held_pose;
  std::optional<SensingChoice> sensing;  // sensing steps of an uncertain object
  Nullable<Clearance> clearance;         // null for steps that do not move the gripper (sensing)
  std::vector<std::string> carried;      // objects assembled into `object` that move with it
  // Phase 2:
  std::optional<bool> inserted;
  // Inserted steps: the preconditions it turned to satisfied (never empty).
  std::optional<std::vector<PreconditionRef>> turned;
  // Phase-2 sensing steps: the pose components the reading corrects (dx dy dz dtheta).
  std::optional<std::vector<std::string>> corrects;
  std::optional<double> finger_opening;  // pickups and squeezes
  std::optional<std::vector<Precondition>> preconditions;
  std::optional<bool> failed;
  std::optional<SensorResidual> sensor_residual_needed;   // failed steps
  std::optional<std::vector<Verification>> verification;  // failed steps
  std::optional<std::vector<Recovery>> recovery;          // failed steps
  std::optional<VisionCheck> vision;  // inserted camera verifications: what PSEIKI must see
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("id", s.id);
    field("action", s.action);
    field("effect", s.effect);
    field("object", s.object);
    field("grasp", s.grasp);
    field("object_pose", s.object_pose);
    field("stable_pose", s.stable_pose);
    field("gripper_pose", s.gripper_pose);
    field("joints", s.joints);
    field("configuration", s.configuration);
    field("fixed_object", s.fixed_object);
    field("fixed_pose", s.fixed_pose);
    field("held_pose", s.held_pose);
    field("sensing", s.sensing);
    field("clearance", s.clearance);
    field("carried", s.carried);
    field("inserted", s.inserted);
    field("turned", s.turned);
    field("corrects", s.corrects);
    field("finger_opening", s.finger_opening);
    field("preconditions", s.preconditions);
    field("failed", s.failed);
    field("sensor_residual_needed", s.sensor_residual_needed);
    field("verification", s.verification);
    field("recovery", s.recovery);
    field("vision", s.vision);
  }
};

// The failing step's preconditions before or after a repair was spliced in.
struct RepairBound {
  Nullable<std::string> name;
  Nullable<std::string> unit;  // m | 1
  double lo{0.0}, hi{0.0};     // SI
  std::string verdict;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("unit", s.unit);
    field("lo", s.lo);
    field("hi", s.hi);
    field("verdict", s.verdict);
  }
};

struct Repair {
  std::string action;  // range-scan | squeeze
  std::string object;
  int for_step{0};  // id of the step whose precondition failed
  bool helped{false};
  std::vector<PreconditionRef> turned;  // as Step::turned
  std::vector<RepairBound> before, after;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("action", s.action);
    field("object", s.object);
    field("for_step", s.for_step);
    field("helped", s.helped);
    field("turned", s.turned);
    field("before", s.before);
    field("after", s.after);
  }
};

struct RangeDisplay {
  std::string unit;
  double lo{0.0}, hi{0.0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("unit", s.unit);
    field("lo", s.lo);
    field("hi", s.hi);
  }
};

struct UncertaintyVariable {
  std::string name;  // dx_peg, dtheta_g3, dy_block_s5
  double lo{0.0}, hi{0.0};
  std::string unit;    // m | rad
  std::string source;  // initial | manipulator | sensor
  Nullable<std::string> object;
  Nullable<int> step;  // execution position (1-based) that allocated it
  RangeDisplay display;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("lo", s.lo);
    field("hi", s.hi);
    field("unit", s.unit);
    field("source", s.source);
    field("object", s.object);
    field("step", s.step);
    field("display", s.display);
  }
};

// ---- the chosen instance's probabilistic analysis (planner/uncertainty/probability.hpp) ----

struct Jacobian {
  std::size_t rows{0}, cols{0}, nonzeros{0};
  double density{0.0};
  std::size_t covariance_nonzeros{0}, non_differentiable{0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("rows", s.rows);
    field("cols", s.cols);
    field("nonzeros", s.nonzeros);
    field("density", s.density);
    field("covariance_nonzeros", s.covariance_nonzeros);
    field("non_differentiable", s.non_differentiable);
  }
};

struct PlanProbability {
  double p_monte_carlo{0.0};
  std::array<double, 2> ci{};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("p_monte_carlo", s.p_monte_carlo);
    field("ci", s.ci);
  }
};

struct PreconditionProbability {
  std::size_t step{0};   // index into Chosen::steps
  std::size_t index{0};  // into that step's preconditions
  std::string name;
  double nominal{0.0}, mean{0.0}, second_order_mean{0.0}, sigma{0.0};
  double p_first_order{0.0}, p_second_order{0.0}, p_monte_carlo{0.0};
  std::array<double, 2> ci{};
  std::size_t violations{0};
  std::optional<std::size_t> samples;  // the points it was evaluated on (fewer when proved)
  bool proved{false};
  bool agrees{false};
  std::string note;
  Nullable<double> allocation_miss;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("step", s.step);
    field("index", s.index);
    field("name", s.name);
    field("nominal", s.nominal);
    field("mean", s.mean);
    field("second_order_mean", s.second_order_mean);
    field("sigma", s.sigma);
    field("p_first_order", s.p_first_order);
    field("p_second_order", s.p_second_order);
    field("p_monte_carlo", s.p_monte_carlo);
    field("ci", s.ci);
    field("violations", s.violations);
    field("samples", s.samples);
    field("proved", s.proved);
    field("agrees", s.agrees);
    field("note", s.note);
    field("allocation_miss", s.allocation_miss);
  }
};

struct ToleranceDisplay {
  std::string unit;
  double half_width{0.0}, allocated{0.0};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("unit", s.unit);
    field("half_width", s.half_width);
    field("allocated", s.allocated);
  }
};

struct ToleranceParameter {
  std::string name;  // <object>.dx, robot.dtheta, range_scan.dy
  std::string source;
  std::string unit;  // m | rad
  double half_width{0.0}, allocated{0.0}, cost{0.0};
  ToleranceDisplay display;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("source", s.source);
    field("unit", s.unit);
    field("half_width", s.half_width);
    field("allocated", s.allocated);
    field("cost", s.cost);
    field("display", s.display);
  }
};

struct Tolerances {
  std::string status;  // not_needed | proved | not_proved | infeasible
  double cost{0.0};
  int rounds{0};
  std::vector<ToleranceParameter> parameters;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("status", s.status);
    field("cost", s.cost);
    field("rounds", s.rounds);
    field("parameters", s.parameters);
  }
};

struct Probability {
  Jacobian jacobian;
  std::size_t samples{0};
  PlanProbability plan;
  std::vector<PreconditionProbability> preconditions;
  Tolerances tolerances;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("jacobian", s.jacobian);
    field("samples", s.samples);
    field("plan", s.plan);
    field("preconditions", s.preconditions);
    field("tolerances", s.tolerances);
  }
};

// The chosen plan instance (or, from PlanRun.analyse, any examined one).
// The repair search for one failing step: counts of what it tried, kept and dropped.
struct RepairSearch {
  int for_step{0};  // id of the failing step
  int candidates{0}, sets_tried{0}, kept{0};
  NamedValues<int> dropped;  // per kind: range-scan, camera-verify, squeeze
  bool holds{false};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("for_step", s.for_step);
    field("candidates", s.candidates);
    field("sets_tried", s.sets_tried);
    field("kept", s.kept);
    field("dropped", s.dropped);
    field("holds", s.holds);
  }
};

// ---- sense planning (planner/sense_planning.hpp): `spar sense-plan --json`, spar.sense_plan ----

// One candidate sensing operation: a sensor at a viewpoint class.
struct SensingCandidate {
  std::string sensor;
  std::string viewpoint;              // a fixed sensor's name, or V1, V2, ... of a wrist sensor
  std::array<double, 3> direction{};  // unit, world, from the object toward the sensor
  bool reachable{true};
  NamedValues<std::string> aspects;  // hypothesis -> the aspect it shows ("" for none)
  // Predicted ambiguity (bits) if each hypothesis were true, and its maximum (absent when the
  // viewpoint is not reachable).
  NamedValues<double> predicted_ambiguity;
  Nullable<double> predicted_max_ambiguity;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("sensor", s.sensor);
    field("viewpoint", s.viewpoint);
    field("direction", s.direction);
    field("reachable", s.reachable);
    field("aspects", s.aspects);
    field("predicted_ambiguity", s.predicted_ambiguity);
    field("predicted_max_ambiguity", s.predicted_max_ambiguity);
  }
};

// One chosen operation; `beliefs` are the pignistic probabilities it leaves in its worst case.
struct SensingOperation {
  std::string sensor;
  std::string viewpoint;
  std::string aspect;  // the aspect the first hypothesis shows it
  NamedValues<std::string> aspects;
  double predicted_max_ambiguity{0.0};
  std::string worst_case;  // the hypothesis of the maximum
  NamedValues<double> beliefs;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("sensor", s.sensor);
    field("viewpoint", s.viewpoint);
    field("aspect", s.aspect);
    field("aspects", s.aspects);
    field("predicted_max_ambiguity", s.predicted_max_ambiguity);
    field("worst_case", s.worst_case);
    field("beliefs", s.beliefs);
  }
};

struct AspectSummary {
  std::string label;
  std::vector<int> faces;
  double solid_angle{0.0};
  std::array<double, 3> direction{};  // object frame
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("label", s.label);
    field("faces", s.faces);
    field("solid_angle", s.solid_angle);
    field("direction", s.direction);
  }
};

// An identity's aspects, and the aspect seen along each of the 320 cell centres of a level-2
// icosphere (object frame): what the report's view-sphere drawing colours.
struct ViewSphere {
  std::string identity;
  std::string method;  // exact arrangement | view sphere
  std::vector<AspectSummary> aspects;
  std::vector<std::array<double, 3>> samples;
  std::vector<std::string> sample_aspects;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("identity", s.identity);
    field("method", s.method);
    field("aspects", s.aspects);
    field("samples", s.samples);
    field("sample_aspects", s.sample_aspects);
  }
};

struct ObjectSensing {
  std::string object;
  std::vector<std::string> hypotheses;
  std::vector<std::string> identities;
  double threshold{0.0};               // bits
  NamedValues<double> beliefs_before;  // pignistic probabilities
  double ambiguity_before{0.0};
  std::vector<SensingCandidate> candidates;
  std::vector<SensingOperation> sequence;
  bool resolved{false};
  NamedValues<double> beliefs_after;  // after the sequence, in its worst case
  double ambiguity_after{0.0};
  std::vector<ViewSphere> view_spheres;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("object", s.object);
    field("hypotheses", s.hypotheses);
    field("identities", s.identities);
    field("threshold", s.threshold);
    field("beliefs_before", s.beliefs_before);
    field("ambiguity_before", s.ambiguity_before);
    field("candidates", s.candidates);
    field("sequence", s.sequence);
    field("resolved", s.resolved);
    field("beliefs_after", s.beliefs_after);
    field("ambiguity_after", s.ambiguity_after);
    field("view_spheres", s.view_spheres);
  }
};

struct SensePlanRecord {
  std::string scenario;
  std::vector<ObjectSensing> objects;  // the uncertain objects
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("scenario", s.scenario);
    field("objects", s.objects);
  }
};

// One outcome of sensing (`branches[]`, normative): the plan of the scenario with the uncertain
// object as the outcome has it, planned and analysed like any plan.
struct Branch {
  std::string outcome;  // the hypothesis: "P1", "cube", "cube:P3"
  std::string object;
  std::string status;         // planned | no_plan (the report's `reason` names the first)
  std::vector<Step> steps;    // the branch's chosen steps (empty without a plan)
  std::optional<int> errors;  // phase 2's
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("outcome", s.outcome);
    field("object", s.object);
    field("status", s.status);
    field("steps", s.steps);
    field("errors", s.errors);
  }
};

struct Chosen {
  std::size_t index{0};  // 0-based, into the enumerated instances
  std::vector<Step> steps;
  // Phase 2 (absent when it did not run):
  std::optional<int> errors;
  std::optional<std::vector<Repair>> repairs;
  std::optional<std::vector<RepairSearch>> repair_searches;
  std::optional<std::vector<UncertaintyVariable>> uncertainty_variables;
  std::optional<Probability> probability;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("index", s.index);
    field("steps", s.steps);
    field("errors", s.errors);
    field("repairs", s.repairs);
    field("repair_searches", s.repair_searches);
    field("uncertainty_variables", s.uncertainty_variables);
    field("probability", s.probability);
  }
};

// ---- the work cell, drawn (reports/internal/cell_svg.hpp) ----

// A closed polygon: [x, y] points in the length unit, the last joined to the first.
using Ring = std::vector<std::array<double, 2>>;

// What is seen of a body from above (world x, y) and from the front (world x, z, looking along
// +y): its silhouette as rings (outer boundaries counter-clockwise, holes clockwise).
struct Silhouette {
  std::vector<Ring> top;
  std::vector<Ring> side;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("top", s.top);
    field("side", s.side);
  }
};

struct CellObject {
  std::string name;
  bool held{false};  // in the gripper
  Silhouette outline;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("held", s.held);
    field("outline", s.outline);
  }
};

// The box of positions an object's frame origin may occupy (world, length unit): sound, the
// bound of its propagated pose error over the instance's uncertainty box.
struct UncertaintyRegion {
  std::string object;
  std::array<double, 3> lo{}, hi{};
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("object", s.object);
    field("lo", s.lo);
    field("hi", s.hi);
  }
};

// Sensing phase 2 inserted: the step and the object it looks at.
struct CellSensing {
  std::string step;  // "#5 range-scan block"
  std::string object;
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("step", s.step);
    field("object", s.object);
  }
};

// The cell after one step of the chosen plan (or in its initial state).
struct CellView {
  Nullable<int> after;  // execution position (1-based) of the step it follows; null: initial
  std::string title;    // "initial state", "after #2 pickup block"
  std::vector<CellObject> objects;
  Nullable<Silhouette> gripper;        // at the step's gripper pose
  Nullable<UncertaintyRegion> region;  // of the object the step handled (held after a pickup)
  std::vector<CellSensing> sensed;     // inserted sensing since the previous view
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("after", s.after);
    field("title", s.title);
    field("objects", s.objects);
    field("gripper", s.gripper);
    field("region", s.region);
    field("sensed", s.sensed);
  }
};

struct CellPlace {
  std::string name;
  double x{0.0}, y{0.0};  // length unit
  double yaw{0.0};        // angle unit
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("x", s.x);
    field("y", s.y);
    field("yaw", s.yaw);
  }
};

// The work cell of the chosen plan: the table top (z = 0) drawn over the region the plan uses,
// the robot's base and reach, the places, and one view per state the plan passes through.
struct Cell {
  std::array<double, 2> table_x{}, table_y{};  // the table top's extent drawn (length unit)
  std::array<double, 3> robot_base{};          // the base frame's origin
  double reach{0.0};     // an upper bound of the gripper's distance from the shoulder (length)
  double shoulder{0.0};  // height of the shoulder (first joint's offset) above the base
  std::vector<CellPlace> places;
  std::vector<CellView> views;  // the initial state, then after each pickup, putdown, assemble
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("table_x", s.table_x);
    field("table_y", s.table_y);
    field("robot_base", s.robot_base);
    field("reach", s.reach);
    field("shoulder", s.shoulder);
    field("places", s.places);
    field("views", s.views);
  }
};

struct Report {
  std::string schema{kReportSchema};
  std::string scenario;
  std::string description;
  std::string status;                 // planned | no_plan
  std::optional<std::string> reason;  // with no_plan
  Units units;
  Robot robot;
  Family family;
  Instances instances;
  Nullable<Chosen> chosen;  // null without a plan; with an uncertain object: its sensing steps
  std::optional<std::vector<ObjectSensing>> sensing;  // with an uncertain object
  std::optional<std::vector<Branch>> branches;        // with an uncertain object, one per outcome
  std::optional<Cell> cell;                           // with a chosen plan
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("schema", s.schema);
    field("scenario", s.scenario);
    field("description", s.description);
    field("status", s.status);
    field("reason", s.reason);
    field("units", s.units);
    field("robot", s.robot);
    field("family", s.family);
    field("instances", s.instances);
    field("chosen", s.chosen);
    field("sensing", s.sensing);
    field("branches", s.branches);
    field("cell", s.cell);
  }
};

// ---- sound bounds of one expression: `spar bound --json`, each line of `--jsonl`, spar.bound ----

struct BoundRecord {
  std::optional<std::string> name;  // a corpus record's name
  double lo{0.0}, hi{0.0};          // sound: every value over the (constrained) box lies inside
  // Attained at argmin / argmax; null when no attained range is known (no_inner_range says why).
  Nullable<double> inner_lo, inner_hi;
  std::optional<std::string> no_inner_range;
  NamedValues<double> argmin, argmax;  // empty when there is no witness
  std::string status;                  // converged | effort_limit | unbounded | infeasible
  bool possibly_undefined{false};
  bool time_limited{false};  // stopped by the time limit (the answer depends on the machine)
  double relative_gap{0.0};
  std::size_t evaluations{0};  // box evaluations
  double seconds{0.0};         // wall-clock time of the bound (varies run to run)
  template <class Self, class Field>
  static void fields(Self& s, Field&& field) {
    field("name", s.name);
    field("lo", s.lo);
    field("hi", s.hi);
    field("inner_lo", s.inner_lo);
    field("inner_hi", s.inner_hi);
    field("no_inner_range", s.no_inner_range);
    field("argmin", s.argmin);
    field("argmax", s.argmax);
    field("status", s.status);
    field("possibly_undefined", s.possibly_undefined);
    field("time_limited", s.time_limited);
    field("relative_gap", s.relative_gap);
    field("evaluations", s.evaluations);
    field("seconds", s.seconds);
  }
};

// The report with `branch`'s steps as its chosen plan (and no branches), to render a branch
// like a plan.
[[nodiscard]] Report branch_as_plan(const Report& report, const Branch& branch);

// ---- naming steps ----

// "#3 pickup block": the step at execution position `position` (0-based) of `chosen`.
[[nodiscard]] std::string step_label(const Chosen& chosen, std::size_t position);
// The execution position of the step with family id `id`, or nullopt.
[[nodiscard]] std::optional<std::size_t> step_position(const Chosen& chosen, int id);

}  // namespace spar::reports

// A numeric twin of phase 2's propagation, for the end-to-end soundness tests: given ACTUAL values
// of every uncertainty variable, it moves the objects through the steps on plain Eigen poses and
// measures each precondition's quantity physically (finger frames against contact points, the
// held mating point against the fixed one). It follows the model stated in
// planner/uncertainty/propagation.hpp, written again from that text: it calls neither Propagation
// nor anything symbolic, and reads the uncertainty variables by provenance (source, object,
// step), never by name. A precondition phase 2 reports satisfied must hold here at every point of
// the box; the symbolic expression must evaluate to the value measured here.
//
// Example:
//   NumericPlan plan(world, analysis.variables, values);   // values: variable name -> value
//   for (std::size_t i = 0; i < analysis.steps.size(); ++i)
//     for (const NumericCondition& c : plan.step(analysis.steps[i].step, int(i) + 1)) use(c);
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spar/planner/uncertainty/analysis.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner::testing {

// One precondition measured at one point: `value relation threshold` should hold.
struct NumericCondition {
  double value{0.0};
  bounds::Relation relation{bounds::Relation::kLess};
  double threshold{0.0};
  [[nodiscard]] bool holds() const {
    switch (relation) {
      case bounds::Relation::kLess:
        return value < threshold;
      case bounds::Relation::kLessEqual:
        return value <= threshold;
      case bounds::Relation::kGreater:
        return value > threshold;
      case bounds::Relation::kGreaterEqual:
        return value >= threshold;
    }
    return false;
  }
};

class NumericPlan {
 public:
  using Pose = Eigen::Isometry3d;

  // `variables` (a space's, with provenance) and `values` (name -> actual value) must outlive
  // this. Every object starts at its scenario pose with its initial error.
  NumericPlan(const WorldModel& world, std::span<const SpaceVariable> variables,
              const std::map<std::string, double>& values)
      : world_(&world),
        variables_(variables),
        values_(&values),
        table_(world.object_count()),
        held_(world.object_count()) {
    for (std::size_t o = 0; o < world.object_count(); ++o)
      table_[o] = Table{world.scenario().objects[o].initial_pose,
                        error(UncertaintySource::kInitial, static_cast<int>(o), -1)};
  }

  // Applies step `index` (1-based position in execution order) and returns its preconditions'
  // values just before it, in the order phase 2 builds them.
  std::vector<NumericCondition> step(const Phase2Step& step, int index) {
    std::vector<NumericCondition> out;
    switch (step.effect) {
      case Effect::kGrasp: {
        const Error arm = error(UncertaintySource::kManipulator, -1, index);
        expect_same_pose(step.object_pose, table_.at(step.object).value().ideal, "grasped", index);
        out = pickup(step, arm);
        held_[step.object] = grip(step, arm);
        table_[step.object].reset();
        break;
      }
      case Effect::kReduce: {
        const Error arm = error(UncertaintySource::kManipulator, -1, index);
        out = pickup(step, arm);
        const Pose h = grip(step, arm);
        table_[step.object] = release(step.object, step.grasp, table_[step.object]->ideal, arm, h);
        break;
      }
      case Effect::kRelease: {
        const Error arm = error(UncertaintySource::kManipulator, -1, index);
        table_[step.object] =
            release(step.object, step.grasp, step.object_pose, arm, held_.at(step.object).value());
        held_[step.object].reset();
        break;
      }
      case Effect::kInsert: {
        const Error arm = error(UncertaintySource::kManipulator, -1, index);
        expect_same_pose(step.fixed_pose, table_.at(step.fixed_object).value().ideal,
                         "fixed object", index);
        out = insertion(step, arm);
        held_[step.object].reset();
        break;
      }
      case Effect::kSense: {
        // The reading corrects the components phase 2 gave a residual; the others keep their
        // actual error (the executor keeps its belief there).
        Error& now = table_.at(step.object).value().error;
        double* slots[4] = {&now.d.x(), &now.d.y(), &now.d.z(), &now.theta};
        for (const PoseComponent component : kPoseComponents)
          if (const std::optional<double> value =
                  find_value(UncertaintySource::kSensor, step.object, index, component))
            *slots[index_of(component)] = *value;
        break;
      }
      case Effect::kNone:
        break;
    }
    return out;
  }

  // The actual world pose of an object on the table (eq. 2).
  [[nodiscard]] Pose actual_on_table(int object) const {
    const Table& table = table_.at(object).value();
    return on_table(table.ideal, table.error);
  }
  [[nodiscard]] bool on_the_table(int object) const { return table_.at(object).has_value(); }

 private:
  struct Error {
    Eigen::Vector3d d{Eigen::Vector3d::Zero()};
    double theta{0.0};
  };
  struct Table {
    Pose ideal;
    Error error;
  };

  // The plan's ideal poses agree with where the objects were left.
  static void expect_same_pose(const Pose& planned, const Pose& tracked, const char* what,
                               int index) {
    EXPECT_LT((planned.matrix() - tracked.matrix()).norm(), 1e-9)
        << what << " pose of step " << index << " is not where the object was left";
  }
  [[nodiscard]] std::optional<double> find_value(UncertaintySource source, int object, int step,
                                                 PoseComponent component) const {
    for (const SpaceVariable& v : variables_)
      if (v.provenance.source == source && v.provenance.object == object &&
          v.provenance.step == step && v.component == component)
        return values_->at(v.name);
    return std::nullopt;
  }
  [[nodiscard]] double value_of(UncertaintySource source, int object, int step,
                                PoseComponent component) const {
    if (const std::optional<double> value = find_value(source, object, step, component))
      return *value;
    ADD_FAILURE() << "no " << to_string(source) << " variable '" << to_string(component)
                  << "' for object " << object << " at step " << step;
    return 0.0;
  }
  [[nodiscard]] Error error(UncertaintySource source, int object, int step) const {
    return {{value_of(source, object, step, PoseComponent::kDx),
             value_of(source, object, step, PoseComponent::kDy),
             value_of(source, object, step, PoseComponent::kDz)},
            value_of(source, object, step, PoseComponent::kDtheta)};
  }
  static Pose rotz(double angle) {
    return Pose(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
  }
  static Pose translation(const Eigen::Vector3d& t) { return Pose(Eigen::Translation3d(t)); }
  // trans(d) Tr_O rotz(θ) R_O.
  static Pose on_table(const Pose& ideal, const Error& error) {
    return translation(error.d + ideal.translation()) * rotz(error.theta) * Pose(ideal.linear());
  }
  // T_ΔM = trans(Δx, Δy, Δz) rotz(Δθ).
  static Pose arm_error(const Error& arm) { return translation(arm.d) * rotz(arm.theta); }
  [[nodiscard]] const geometry::Grasp& grasp_of(int object, int grasp) const {
    return world_->object(object).grasps.at(grasp);
  }

  // The four pickup conditions [0,1,0,0] P_f^-1 C_c, measured.
  std::vector<NumericCondition> pickup(const Phase2Step& step, const Error& arm) const {
    const Table& table = table_.at(step.object).value();
    const geometry::Grasp& grasp = grasp_of(step.object, step.grasp);
    const Pose& t_g = grasp.gripper_in_object;
    const Pose ideal_gripper = table.ideal * t_g;
    const Pose object = on_table(table.ideal, table.error);
    const double w_m = world_->gripper().max_opening, w_g = grasp.width;
    std::vector<NumericCondition> out;
    for (int finger = 0; finger < 2; ++finger) {
      const Pose p =
          ideal_gripper * arm_error(arm) * translation({0, finger == 0 ? -w_m / 2 : w_m / 2, 0});
      for (int contact = 0; contact < 2; ++contact) {
        const Eigen::Vector3d c =
            object * t_g * Eigen::Vector3d(0, contact == 0 ? w_g / 2 : -w_g / 2, 0);
        out.push_back({(p.inverse() * c).y(),
                       finger == 0 ? bounds::Relation::kGreater : bounds::Relation::kLess, 0.0});
      }
    }
    return out;
  }

  // H = T_ΔM^-1 trans(q_x, Δy, q_z) rotz(Δθ), q the grasp centre in the ideal gripper frame.
  Pose grip(const Phase2Step& step, const Error& arm) const {
    const Table& table = table_.at(step.object).value();
    const Pose& t_g = grasp_of(step.object, step.grasp).gripper_in_object;
    const Eigen::Vector3d q =
        (table.ideal * t_g).inverse() * (on_table(table.ideal, table.error) * t_g.translation());
    return arm_error(arm).inverse() * translation({q.x(), arm.d.y(), q.z()}) * rotz(arm.theta);
  }

  // Put down at `ideal`: the actual pose M T_ΔM H T_G^-1 back in eq. 2 form, the angle of its
  // rotation error about the approach axis a counted about world z by the sign of a_z.
  Table release(int object, int grasp, const Pose& ideal, const Error& arm, const Pose& h) const {
    const Pose& t_g = grasp_of(object, grasp).gripper_in_object;
    const Pose m = ideal * t_g;
    const Pose actual = m * arm_error(arm) * h * t_g.inverse();
    const Eigen::Matrix3d turn = actual.linear() * ideal.linear().transpose();
    const Eigen::Vector3d a = m.linear().col(2);
    const Eigen::Vector3d axis_sin(turn(2, 1) - turn(1, 2), turn(0, 2) - turn(2, 0),
                                   turn(1, 0) - turn(0, 1));
    const double angle = std::atan2(0.5 * axis_sin.dot(a), 0.5 * (turn.trace() - 1));
    // The model: the turn is a rotation about a (exact while the grip carries no rotation).
    EXPECT_NEAR((turn - Eigen::Matrix3d(Eigen::AngleAxisd(angle, a))).norm(), 0.0, 1e-9);
    return {ideal, {actual.translation() - ideal.translation(), a.z() >= 0 ? angle : -angle}};
  }

  // -c <= δ·u1 <= c, -c <= δ·u2 <= c and (R_f^T R_h R_a^T v)·v >= cos α, measured.
  std::vector<NumericCondition> insertion(const Phase2Step& step, const Error& arm) const {
    const Scenario& scenario = world_->scenario();
    const std::string& held_name = scenario.objects[step.object].name;
    const std::string& fixed_name = scenario.objects[step.fixed_object].name;
    const AssembledGoal* goal = nullptr;
    for (const Goal& g : scenario.goals)
      if (const auto* a = std::get_if<AssembledGoal>(&g);
          a != nullptr && a->held == held_name && a->fixed == fixed_name)
        goal = a;
    if (goal == nullptr) {
      ADD_FAILURE() << "no goal assembles " << held_name << " into " << fixed_name;
      return {};
    }
    const Pose& t_g = grasp_of(step.object, step.grasp).gripper_in_object;
    const Pose held =
        step.object_pose * t_g * arm_error(arm) * held_.at(step.object).value() * t_g.inverse();
    const Pose fixed = actual_on_table(step.fixed_object);
    const Pose relative = fixed.inverse() * held;
    const geometry::ObjectModel& model = scenario.objects[step.object].model;
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    double area = 0;
    for (const int face : goal->held_faces) {
      weighted += model.face(face).area * model.face(face).centroid;
      area += model.face(face).area;
    }
    const Eigen::Vector3d p = weighted / area;
    const Eigen::Vector3d delta = relative * p - goal->relative * p;
    const Eigen::Vector3d v = goal->mating_vector.normalized();
    const Eigen::Vector3d u1 = v.unitOrthogonal(), u2 = v.cross(u1);
    const double c = goal->clearance;
    std::vector<NumericCondition> out;
    for (const Eigen::Vector3d& u : {u1, u2}) {
      out.push_back({delta.dot(u), bounds::Relation::kLessEqual, c});
      out.push_back({delta.dot(u), bounds::Relation::kGreaterEqual, -c});
    }
    if (goal->angular_clearance > 0)
      out.push_back({(relative.linear() * goal->relative.linear().transpose() * v).dot(v),
                     bounds::Relation::kGreaterEqual, std::cos(goal->angular_clearance)});
    return out;
  }

  const WorldModel* world_;
  std::span<const SpaceVariable> variables_;
  const std::map<std::string, double>* values_;
  std::vector<std::optional<Table>> table_;  // per object, while on the table
  std::vector<std::optional<Pose>> held_;    // per object: its grip H while held
};

}  // namespace spar::planner::testing

// Plan instances: a plan family made concrete (seed 001, "Representation of Plans"). An instance is
// one consistent labeling of the constraint network (a grasp label for every grasp variable, a
// position label for every position variable) together with one linearization of the ordering
// graph; it fixes every pose, grasp transform and joint configuration of the plan.
//
// Enumeration is lazy and deterministic: labelings in the network's lexicographic order (outer),
// for each the linearizations lexicographically smallest first (inner), up to a limit. Phase 2
// examines instances in this order; until it has chosen, the first one is the plan.
//
// Per step (in execution order), for manipulations: the grasp (object's grasp label), the object's
// world pose when the step starts (for a putdown and an assembly: where the step puts it), the
// gripper frame's world pose at the grasp, T = T_O T_G (assembly: T = T_fixed Ta T_G), and the
// IK branch it uses (the first in-limit one, in the robot's order, whose arm clears the table and,
// once the instance is checked, every object: world.hpp, "The arm").
//
// Only collision-free instances are returned: each is simulated on a WorldState from the initial
// world (objects move with what is assembled into them) and every step's motions are checked
// (world.hpp: WorldModel::check_grasp / check_insertion, approach and retreat included); an
// instance with a conflict is skipped. Each step records what it carries and its clearance. At
// most `max_examined` instances are simulated per enumerator; after that next() says none.
//
// Example:
//   const PlanFamily family = post_plan(world, domain);
//   InstanceEnumerator instances(family, world, domain);
//   while (std::optional<PlanInstance> instance = instances.next())
//     for (const InstanceStep& step : instance->steps) std::cout << step.action_name << '\n';
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "spar/planner/posting.hpp"

namespace spar::planner {

struct InstanceStep {
  int step{0};    // family step id
  int action{0};  // index into Domain::actions
  std::string action_name;
  int object{-1};       // the object the step handles (the held one for an assembly)
  int grasp{-1};        // grasp label of `object`, -1 for steps without a grasp
  int position{-1};     // position label of the step's position parameter
  int stable_pose{-1};  // of the object at `object_pose`, -1 if none
  kinematics::Transform object_pose{kinematics::Transform::Identity()};
  kinematics::Transform gripper_pose{kinematics::Transform::Identity()};  // valid if grasp >= 0
  // Of gripper_pose: its tilt, and (once check_collisions ran) the collision-checked IK branch
  // the step uses, the one reports show and joint uncertainty acts at.
  Reach reach;
  // Objects assembled into `object` (directly or not) that move with it in this step.
  std::vector<int> carried;
  // The step's collision check: clearance at its configuration and the nearest other object.
  StepCheck collision;
  // Assembly steps (the position belongs to another object than the grasp):
  int fixed_object{-1};
  kinematics::Transform fixed_pose{kinematics::Transform::Identity()};
  kinematics::Transform held_pose{kinematics::Transform::Identity()};  // T_fixed Ta
  [[nodiscard]] bool is_assembly() const { return fixed_object >= 0; }
};

struct PlanInstance {
  std::size_t index{0};       // position in the enumeration
  std::vector<int> labeling;  // label of every network variable id
  std::vector<int> order;     // family step ids of the actions, in execution order
  std::vector<InstanceStep> steps;
};

class InstanceEnumerator {
 public:
  // The family, world and domain must outlive the enumerator. Throws PlanError unless the family
  // is planned.
  // `measure`: fill each step's clearance (else only the verdict is computed, which is what
  // deciding whether a family has a collision-free instance needs).
  InstanceEnumerator(const PlanFamily& family, const WorldModel& world, const Domain& domain,
                     std::size_t max_examined = 20'000, bool measure = true);

  // The next collision-free instance, or nullopt when every labeling x linearization has been
  // examined (or max_examined of them).
  [[nodiscard]] std::optional<PlanInstance> next();
  // Instances simulated so far, those refused for a collision, and the first refusal
  // ("pickup(block, G3, initial): the open gripper, coming to block, hits cube").
  [[nodiscard]] std::size_t examined() const { return examined_; }
  [[nodiscard]] std::size_t refused() const { return refused_; }
  [[nodiscard]] const std::string& first_conflict() const { return first_conflict_; }

 private:
  [[nodiscard]] PlanInstance build(const std::vector<int>& labeling,
                                   const std::vector<int>& order) const;

  const PlanFamily& family_;
  const WorldModel& world_;
  const Domain& domain_;
  cms::Labelings labelings_;
  std::optional<std::vector<int>> labeling_;   // the current labeling
  std::optional<cms::Linearizations> orders_;  // of the current labeling
  std::size_t count_{0};
  std::size_t max_examined_;
  bool measure_;
  std::size_t examined_{0};
  std::size_t refused_{0};
  std::string first_conflict_;
};

// What `step` does to the world: a release or an insertion puts its object (and what it carries)
// down, a lift marks it held, sensing changes nothing.
void apply_step(WorldState& state, const InstanceStep& step, const Domain& domain);

// Simulates `instance` from the initial world and checks each step's motions and, after each
// release, that the subassembly released stands on the table (WorldModel::check_rest), filling
// each step's `carried` and `collision` (its clearance only when `measure`); returns the first
// conflict, or nullopt when there is none.
[[nodiscard]] std::optional<std::string> check_collisions(PlanInstance& instance,
                                                          const WorldModel& world,
                                                          const Domain& domain,
                                                          bool measure = true);

struct InstanceList {
  std::vector<PlanInstance> instances;
  bool limit_reached{false};  // more instances exist than `limit`
};

[[nodiscard]] InstanceList enumerate_instances(const PlanFamily& family, const WorldModel& world,
                                               const Domain& domain, std::size_t limit);

}  // namespace spar::planner

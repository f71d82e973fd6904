// kinematics benchmark: Puma 560 forward kinematics and closed-form inverse kinematics (all eight
// configurations with joint-limit checks) against Orocos KDL, in the same run; and the inverse
// kinematics of the UR5 and the Panda (spar's closed forms and numeric solver vs KDL's LMA and
// NR-JL with random restarts, success rate and time per solve on the same random poses):
//   FK: spar DhChain::forward            vs KDL ChainFkSolverPos_recursive
//   IK: spar PumaIk::solve (8 solutions)  vs KDL ChainIkSolverPos_LMA (one solution, no limits,
//       seeded within 0.3 rad of the answer, as in the corpus's peer_check_orocos_kdl notes)
// Prints a table and `ratio <workload> <peer> <peer_time/our_time>` lines. `--quick` runs fewer
// repetitions (well under 60 s).
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/chainiksolverpos_nr_jl.hpp>
#include <kdl/chainiksolvervel_pinv.hpp>
#include <kdl/frames.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <random>
#include <span>
#include <vector>

#include "spar/bounds/interval.hpp"
#include "spar/common/units.hpp"
#include "spar/kinematics/ik.hpp"
#include "spar/kinematics/pickup_check.hpp"
#include "spar/kinematics/pickup_template.hpp"
#include "spar/kinematics/puma.hpp"
#include "spar/kinematics/robots.hpp"
#include "spar/symbolic/tape.hpp"

namespace {

using spar::kinematics::DhChain;
using spar::kinematics::JointVector;
using spar::kinematics::PumaIk;
using spar::kinematics::Transform;
using Clock = std::chrono::steady_clock;

struct BenchOptions {
  bool quick{false};
};

// Seconds per call of `body(i)` for i over `count` items, repeated `repetitions` times.
template <typename Body>
double seconds_per_call(int repetitions, int count, Body&& body) {
  const Clock::time_point start = Clock::now();
  for (int repetition = 0; repetition < repetitions; ++repetition)
    for (int i = 0; i < count; ++i) body(i);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  return elapsed.count() / (static_cast<double>(repetitions) * count);
}

void print_row(const char* workload, const char* implementation, double seconds, const char* note) {
  std::printf("%-10s %-40s %10.3f us/call   %s\n", workload, implementation, seconds * 1e6, note);
}

KDL::Chain kdl_chain(const DhChain& robot) {
  KDL::Chain chain;
  for (const spar::kinematics::DhJoint& joint : robot.joints()) {
    chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::RotZ),
                                  KDL::Frame::DH(joint.a, joint.alpha, joint.d, joint.offset)));
  }
  return chain;
}

KDL::Frame kdl_frame(const Transform& pose) {
  const Eigen::Matrix3d& r = pose.linear();
  const Eigen::Vector3d& p = pose.translation();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0),
                                  r(2, 1), r(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

// The largest entry of |KDL's frame - spar's pose| (rotation and translation alike).
double frame_disagreement(const KDL::Frame& frame, const Transform& pose) {
  double most = 0.0;
  for (int r = 0; r < 3; ++r) {
    most = std::max(most, std::abs(frame.p(r) - pose.translation()[r]));
    for (int c = 0; c < 3; ++c)
      most = std::max(most, std::abs(frame.M(r, c) - pose.linear()(r, c)));
  }
  return most;
}

// Random joint vectors of the Puma 560 within its limits, their flange poses, and KDL's copies
// (with seeds for its iterative IK, 0.3 rad off).
struct PumaSamples {
  std::vector<JointVector> joints;
  std::vector<KDL::JntArray> kdl_joints, kdl_seeds;
  std::vector<Transform> poses;
};

PumaSamples puma_samples(const DhChain& robot, int count) {
  std::mt19937_64 random(20260523);
  PumaSamples out{
      std::vector<JointVector>(count), std::vector<KDL::JntArray>(count, KDL::JntArray(6)),
      std::vector<KDL::JntArray>(count, KDL::JntArray(6)), std::vector<Transform>(count)};
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> seed_noise(-0.3, 0.3);
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j < 6; ++j) {
      const auto& limits = robot.joint(static_cast<std::size_t>(j)).limits;
      out.joints[i][j] = limits.lower + (limits.upper - limits.lower) * unit(random);
      out.kdl_joints[i](j) = out.joints[i][j];
      out.kdl_seeds[i](j) = out.joints[i][j] + seed_noise(random);
    }
  }
  for (int i = 0; i < count; ++i)
    out.poses[i] = robot.forward(std::span<const double>(out.joints[i].data(), 6));
  return out;
}

// Agreement check before timing: the same FK as KDL, and spar's IK contains the generating q.
void check_puma(const PumaSamples& samples, const PumaIk& solver,
                KDL::ChainFkSolverPos_recursive& kdl_fk) {
  const int count = static_cast<int>(samples.joints.size());
  double fk_disagreement = 0.0;
  int ik_contains_q = 0;
  for (int i = 0; i < count; ++i) {
    KDL::Frame frame;
    kdl_fk.JntToCart(samples.kdl_joints[i], frame);
    fk_disagreement = std::max(fk_disagreement, frame_disagreement(frame, samples.poses[i]));
    const spar::kinematics::IkResult result = solver.solve(samples.poses[i]);
    for (const auto& solution : result.solutions) {
      double distance = 0.0;
      for (int j = 0; j < 6; ++j)
        distance = std::max(
            distance, std::abs(spar::kinematics::wrap_angle(solution.q[j] - samples.joints[i][j])));
      if (result.solved() && distance < 1e-7) {
        ++ik_contains_q;
        break;
      }
    }
  }
  std::printf(
      "check: max |FK spar - FK KDL| = %.2e over %d joint vectors; spar IK contains q for "
      "%d/%d\n",
      fk_disagreement, count, ik_contains_q, count);
}

// Forward and inverse kinematics of the Puma 560, spar vs KDL.
void run_numeric_kinematics(const BenchOptions& options) {
  const DhChain& robot = spar::kinematics::puma560();
  const PumaIk solver(robot);
  const KDL::Chain chain = kdl_chain(robot);
  const int count = 1000;
  const PumaSamples samples = puma_samples(robot, count);
  KDL::ChainFkSolverPos_recursive kdl_fk(chain);
  check_puma(samples, solver, kdl_fk);

  const int fk_repetitions = options.quick ? 200 : 2000;
  const int ik_repetitions = options.quick ? 200 : 2000;
  const int lma_count = options.quick ? 200 : 1000;

  double checksum = 0.0;
  const double our_fk = seconds_per_call(fk_repetitions, count, [&](int i) {
    const Transform pose = robot.forward(std::span<const double>(samples.joints[i].data(), 6));
    checksum += pose.translation().x() + pose.linear()(2, 1);
  });
  KDL::Frame frame;
  const double kdl_fk_time = seconds_per_call(fk_repetitions, count, [&](int i) {
    kdl_fk.JntToCart(samples.kdl_joints[i], frame);
    checksum += frame.p.x() + frame.M(2, 1);
  });

  int in_limits = 0;
  const double our_ik = seconds_per_call(ik_repetitions, count, [&](int i) {
    const spar::kinematics::IkResult result = solver.solve(samples.poses[i]);
    in_limits += result.count_within_limits();
    checksum += result.solutions[7].q[5];
  });

  KDL::ChainIkSolverPos_LMA kdl_ik(chain);
  KDL::JntArray kdl_out(6);
  std::vector<KDL::Frame> kdl_targets(count);
  for (int i = 0; i < count; ++i) kdl_targets[i] = kdl_frame(samples.poses[i]);
  int converged = 0;
  const double kdl_ik_time = seconds_per_call(1, lma_count, [&](int i) {
    converged += kdl_ik.CartToJnt(samples.kdl_seeds[i], kdl_targets[i], kdl_out) >= 0 ? 1 : 0;
    checksum += kdl_out(0);
  });

  char note[128];
  std::printf("\n%-10s %-40s %10s\n", "workload", "implementation", "time");
  print_row("fk", "spar DhChain::forward", our_fk, "");
  print_row("fk", "KDL ChainFkSolverPos_recursive", kdl_fk_time, "");
  std::snprintf(note, sizeof note, "8 solutions + limits; %.2f in limits per pose",
                static_cast<double>(in_limits) / (static_cast<double>(ik_repetitions) * count));
  print_row("ik", "spar PumaIk::solve (all 8)", our_ik, note);
  std::snprintf(note, sizeof note, "1 solution, no limits; converged %d/%d", converged, lma_count);
  print_row("ik", "KDL ChainIkSolverPos_LMA", kdl_ik_time, note);
  std::printf("\nratio fk kdl %.2f\n", kdl_fk_time / our_fk);
  std::printf("ratio ik_all8 kdl_lma %.1f\n", kdl_ik_time / our_ik);
  std::printf("target ik_all8 under 2 us: %s (%.3f us)\n", our_ik < 2e-6 ? "met" : "MISSED",
              our_ik * 1e6);
  std::printf("(checksum %.6g)\n", checksum);
}

// A rigid transform with interval entries (the bottom row 0 0 0 1 is exact and left out): the
// direct interval implementation of the pickup check multiplies these, no symbolic work at all.
struct IntervalPose {
  spar::bounds::Interval rotation[3][3];
  spar::bounds::Interval translation[3];
};

IntervalPose interval_pose(const Transform& pose) {
  IntervalPose result;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) result.rotation[i][j] = pose.linear()(i, j);
    result.translation[i] = pose.translation()(i);
  }
  return result;
}

// trans(x, y, z) rotz(theta).
IntervalPose interval_pose(const spar::bounds::Interval& x, const spar::bounds::Interval& y,
                           const spar::bounds::Interval& z, const spar::bounds::Interval& theta) {
  IntervalPose result;
  const spar::bounds::Interval c = cos(theta), s = sin(theta);
  result.rotation[0][0] = c;
  result.rotation[0][1] = -s;
  result.rotation[1][0] = s;
  result.rotation[1][1] = c;
  result.rotation[2][2] = 1.0;
  result.translation[0] = x;
  result.translation[1] = y;
  result.translation[2] = z;
  return result;
}

IntervalPose operator*(const IntervalPose& a, const IntervalPose& b) {
  IntervalPose result;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      result.rotation[i][j] = a.rotation[i][0] * b.rotation[0][j] +
                              a.rotation[i][1] * b.rotation[1][j] +
                              a.rotation[i][2] * b.rotation[2][j];
    }
    result.translation[i] = a.rotation[i][0] * b.translation[0] +
                            a.rotation[i][1] * b.translation[1] +
                            a.rotation[i][2] * b.translation[2] + a.translation[i];
  }
  return result;
}

// (R, t)^-1 = (R^T, -R^T t).
IntervalPose rigid_inverse(const IntervalPose& a) {
  IntervalPose result;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) result.rotation[i][j] = a.rotation[j][i];
    result.translation[i] =
        -(a.rotation[0][i] * a.translation[0] + a.rotation[1][i] * a.translation[1] +
          a.rotation[2][i] * a.translation[2]);
  }
  return result;
}

// SPAR's pickup preconditions (the peg example, Table 2 bounds), decided per plan instance. The
// example is in metres; widths are printed in inches, like the paper's.
//   ours, fresh: a fresh pool, the uncertain poses, the four inequalities built right to left
//          (kinematics/pickup.hpp), one tape compiled for all four (PickupChecker) and checked
//          (one natural interval evaluation + one at the centre; bound() only if undecided)
//   ours, reused: PickupChecker::check on an already compiled checker with a new box (what a
//          planner pays when an instance's geometry is unchanged and only the bounds change:
//          sensing, widening); each repetition alternates between two boxes
//   naive: the same poses multiplied as full 4x4 products left to right, (P^-1 C) as a matrix,
//          compiled to a tape and bounded by one natural interval evaluation (SPAR-era plain
//          interval check), in the same run.
//   ours, template: PickupTemplate (kinematics/pickup_template.hpp) built once per pair of
//          uncertainty models (its one-time cost timed apart); per instance only the geometry's
//          parameters and the check. Instances alternate between three geometries (the example,
//          its grasp shifted 0.5 in along the peg, the peg turned 40 degrees) so none is a repeat
//   naive direct: the same 4x4 products with bounds::Interval entries (interval sin/cos of the
//          angle boxes, rigid inverses), no symbolic work at all: a direct interval implementation
// Also times the phases of the fresh path separately: build only, build + compile.

// What one way of checking the pickup preconditions did: time per instance, inequalities proved,
// full bound() calls, and the summed widths (of the example's instances where they alternate).
struct PickupRun {
  double seconds{0};
  int runs{0}, examples{0}, proved{0}, full_bounds{0};
  double width{0};
  [[nodiscard]] double per_run(int count) const { return static_cast<double>(count) / runs; }
  // Mean width of an inequality of the example, in inches.
  [[nodiscard]] double mean_width() const { return width / (4.0 * examples) / spar::units::kInch; }
};

// Tallies one instance's checks into `run` (widths only for the example, index 0).
void tally(PickupRun& run, std::span<const spar::kinematics::PickupCheck> checks, bool example) {
  for (const spar::kinematics::PickupCheck& check : checks) {
    run.proved += check.verdict == spar::bounds::Verdict::kSatisfied ? 1 : 0;
    run.full_bounds += check.bound.evaluations > 1 ? 1 : 0;
    if (example) run.width += check.bound.hi - check.bound.lo;
  }
}

// spar fresh: the poses, the four expressions, compile and check, every instance.
PickupRun fresh_pickups(const spar::kinematics::PickupGeometry& geometry, int repetitions) {
  using namespace spar::kinematics;
  PickupRun run{.runs = repetitions, .examples = repetitions};
  run.seconds = seconds_per_call(repetitions, 1, [&](int) {
    spar::symbolic::ExprPool pool;
    const UncertainManipulator gripper(pool, kTable2Gripper);
    const UncertainObject peg(pool, kTable2Object);
    tally(run, check_pickup(pickup_preconditions(geometry, gripper, peg)), true);
  });
  return run;
}

// spar reused: one PickupChecker, two boxes alternating.
PickupRun reused_pickups(const spar::kinematics::PickupGeometry& geometry, int repetitions) {
  using namespace spar::kinematics;
  spar::symbolic::ExprPool pool;
  const UncertainManipulator gripper(pool, kTable2Gripper);
  const UncertainObject peg(pool, kTable2Object);
  const PickupPreconditions preconditions = pickup_preconditions(geometry, gripper, peg);
  PickupChecker checker(preconditions);
  std::vector<UncertaintyVariable> boxes[2] = {preconditions.variables, preconditions.variables};
  for (UncertaintyVariable& v : boxes[1]) {
    v.lower *= 0.5;
    v.upper *= 0.5;
  }
  PickupRun run{.runs = repetitions, .examples = repetitions};
  int call = 0;
  run.seconds = seconds_per_call(repetitions, 1,
                                 [&](int) { tally(run, checker.check(boxes[call++ & 1]), false); });
  return run;
}

// naive: the same 4x4 products built symbolically, compiled to a tape and bounded by one natural
// interval evaluation.
PickupRun naive_tape_pickups(const spar::kinematics::PickupGeometry& geometry, int repetitions) {
  using namespace spar::kinematics;
  using spar::bounds::Interval;
  PickupRun run{.runs = repetitions, .examples = repetitions};
  run.seconds = seconds_per_call(repetitions, 1, [&](int) {
    spar::symbolic::ExprPool pool;
    const UncertainManipulator gripper(pool, kTable2Gripper);
    const UncertainObject peg(pool, kTable2Object);
    const SymbolicTransform grasp = SymbolicTransform::from_numeric(pool, geometry.grasp);
    const SymbolicTransform ideal_gripper =
        SymbolicTransform::from_numeric(pool, geometry.object_pose) * grasp * gripper.error();
    const SymbolicTransform object = peg.possible_pose(geometry.object_pose) * grasp;
    const double half_opening = geometry.finger_opening / 2, half_width = geometry.object_width / 2;
    std::vector<spar::symbolic::Expr> conditions, variables;
    for (const double finger : {-half_opening, half_opening}) {
      const SymbolicTransform inverse = rigid_inverse(ideal_gripper * trans(pool, 0, finger, 0));
      for (const double contact : {half_width, -half_width}) {
        conditions.push_back((inverse * object * trans(pool, 0, contact, 0)).translation()[1]);
      }
    }
    std::vector<Interval> box;
    for (const auto& variables_of : {gripper.variables(), peg.variables()}) {
      for (const UncertaintyVariable& v : variables_of) {
        variables.push_back(pool.variable(v.name));
        box.emplace_back(v.lower, v.upper);
      }
    }
    const spar::symbolic::Tape tape = spar::symbolic::Tape::compile(conditions, variables);
    spar::symbolic::TapeEvaluator<Interval> evaluator(tape);
    Interval out[4];
    evaluator.evaluate(box, out);
    for (int i = 0; i < 4; ++i) {
      run.proved += (i < 2 ? out[i].lo > 0 : out[i].hi < 0) ? 1 : 0;
      run.width += out[i].hi - out[i].lo;
    }
  });
  return run;
}

// spar template: PickupTemplate built once, checked on the instances in turn.
PickupRun template_pickups(const std::array<spar::kinematics::PickupGeometry, 3>& instances,
                           int repetitions) {
  spar::kinematics::PickupTemplate pickup(spar::kinematics::kTable2Gripper,
                                          spar::kinematics::kTable2Object);
  PickupRun run{.runs = repetitions};
  std::size_t next_instance = 0;
  run.seconds = seconds_per_call(repetitions, 1, [&](int) {
    const std::size_t index = next_instance++ % instances.size();
    run.examples += index == 0 ? 1 : 0;
    tally(run, pickup.check(instances[index]), index == 0);
  });
  return run;
}

// naive direct: the same 4x4 products with bounds::Interval entries, no symbolic work at all.
PickupRun direct_pickups(const std::array<spar::kinematics::PickupGeometry, 3>& instances,
                         int repetitions) {
  using namespace spar::kinematics;
  using spar::bounds::Interval;
  PickupRun run{.runs = repetitions};
  std::size_t next_instance = 0;
  run.seconds = seconds_per_call(repetitions, 1, [&](int) {
    const std::size_t index = next_instance++ % instances.size();
    run.examples += index == 0 ? 1 : 0;
    const PickupGeometry& instance = instances[index];
    const auto box = [](double half_width) { return Interval{-half_width, half_width}; };
    const IntervalPose manipulator_error =
        interval_pose(box(kTable2Gripper.dx), box(kTable2Gripper.dy), box(kTable2Gripper.dz),
                      box(kTable2Gripper.dtheta));
    // T_O+Δ = Tr_ΔO Tr_O R_ΔO R_O.
    const Eigen::Vector3d& t_o = instance.object_pose.translation();
    Transform r_o = Transform::Identity();
    r_o.linear() = instance.object_pose.linear();
    const IntervalPose object =
        interval_pose(box(kTable2Object.dx) + t_o.x(), box(kTable2Object.dy) + t_o.y(),
                      box(kTable2Object.dz) + t_o.z(), box(kTable2Object.dtheta)) *
        interval_pose(r_o);
    const IntervalPose grasp = interval_pose(instance.grasp);
    const IntervalPose gripper = interval_pose(instance.object_pose) * grasp * manipulator_error;
    const double half_opening = instance.finger_opening / 2, half_width = instance.object_width / 2;
    int condition = 0;
    for (const double finger : {-half_opening, half_opening}) {
      const IntervalPose inverse =
          rigid_inverse(gripper * interval_pose(Transform(Eigen::Translation3d(0, finger, 0))));
      for (const double contact : {half_width, -half_width}) {
        const IntervalPose in_finger =
            inverse * object * grasp *
            interval_pose(Transform(Eigen::Translation3d(0, contact, 0)));
        const Interval y = in_finger.translation[1];
        run.proved += (condition++ < 2 ? y.lo > 0 : y.hi < 0) ? 1 : 0;
        if (index == 0) run.width += y.hi - y.lo;
      }
    }
  });
  return run;
}

void run_pickup_preconditions(const BenchOptions& options) {
  using namespace spar::kinematics;
  const PickupGeometry geometry = peg_pickup_example();
  const int repetitions = options.quick ? 3000 : 30000;

  const PickupRun ours = fresh_pickups(geometry, repetitions);
  // The fresh path's phases apart: build only, build + compile.
  std::size_t nodes = 0;
  const double build_only = seconds_per_call(repetitions, 1, [&](int) {
    spar::symbolic::ExprPool pool;
    const UncertainManipulator gripper(pool, kTable2Gripper);
    const UncertainObject peg(pool, kTable2Object);
    nodes += pickup_preconditions(geometry, gripper, peg).variables.size();
  });
  const double build_compile = seconds_per_call(repetitions, 1, [&](int) {
    spar::symbolic::ExprPool pool;
    const UncertainManipulator gripper(pool, kTable2Gripper);
    const UncertainObject peg(pool, kTable2Object);
    const PickupChecker checker(pickup_preconditions(geometry, gripper, peg));
    nodes += 1;
  });
  const PickupRun reused = reused_pickups(geometry, repetitions * 10);
  const PickupRun naive = naive_tape_pickups(geometry, repetitions);

  int template_built = 0;
  const double template_build = seconds_per_call(repetitions / 10, 1, [&](int) {
    const PickupTemplate built(kTable2Gripper, kTable2Object);
    template_built += static_cast<int>(built.variables().size());
  });
  std::array<PickupGeometry, 3> instances{geometry, geometry, geometry};
  instances[1].grasp = Eigen::Translation3d(0.5 * spar::units::kInch, 0, 0) * geometry.grasp;
  instances[2].object_pose = Eigen::Translation3d(geometry.object_pose.translation()) *
                             Eigen::AngleAxisd(40 * spar::units::kDegree, Eigen::Vector3d::UnitZ());
  // Widths are summed over the example's instances only, to compare with the rows above.
  const PickupRun templated = template_pickups(instances, repetitions * 10);
  const PickupRun direct = direct_pickups(instances, repetitions * 10);

  char note[160];
  std::printf("\npickup preconditions, one plan instance = build + decide 4 inequalities\n");
  std::snprintf(note, sizeof note, "proved %.2f/4, full bound() on %.2f/4, mean width %.4f in",
                ours.per_run(ours.proved), ours.per_run(ours.full_bounds), ours.mean_width());
  print_row("pickup", "spar fresh: build + compile + check", ours.seconds, note);
  print_row("pickup", "  phase: build poses + 4 expressions", build_only, "");
  print_row("pickup", "  phase: build + compile 1 tape", build_compile, "");
  std::snprintf(note, sizeof note, "proved %.2f/4 (two boxes alternating)",
                reused.per_run(reused.proved));
  print_row("pickup", "spar reused checker: check only", reused.seconds, note);
  std::snprintf(note, sizeof note, "proved %.2f/4, mean width %.4f in", naive.per_run(naive.proved),
                naive.mean_width());
  print_row("pickup", "naive 4x4 products + interval tape", naive.seconds, note);
  std::snprintf(note, sizeof note,
                "proved %.2f/4, full bound() on %.2f/4, mean width %.4f in (on the example)",
                templated.per_run(templated.proved), templated.per_run(templated.full_bounds),
                templated.mean_width());
  print_row("pickup", "spar template: fresh geometry, check", templated.seconds, note);
  std::snprintf(note, sizeof note, "once per pair of uncertainty models (checksum %d)",
                template_built / (repetitions / 10));
  print_row("pickup", "  spar template: one-time build", template_build, note);
  std::snprintf(note, sizeof note, "proved %.2f/4, mean width %.4f in (on the example)",
                direct.per_run(direct.proved), direct.mean_width());
  print_row("pickup", "naive direct interval 4x4", direct.seconds, note);
  std::printf(
      "per inequality: spar fresh %.3f us, spar reused %.3f us, naive %.3f us "
      "(target: well under ~8 us)\n",
      ours.seconds * 1e6 / 4, reused.seconds * 1e6 / 4, naive.seconds * 1e6 / 4);
  std::printf("ratio pickup_instance naive_interval %.2f\n", naive.seconds / ours.seconds);
  std::printf("ratio pickup_recheck naive_interval %.2f\n", naive.seconds / reused.seconds);
  std::printf("ratio pickup_template naive_interval %.2f\n", naive.seconds / templated.seconds);
  std::printf("ratio pickup_template naive_direct_interval %.2f\n",
              direct.seconds / templated.seconds);
  std::printf("(pickup checksum %zu)\n", nodes);
}

// ---- inverse kinematics of the URDF robots (issue 23) ----

// A solver solved a pose when it returned an in-limit joint vector whose FK (spar's) reproduces
// the pose to this (every entry of the 4x4 matrix): one criterion for every solver. KDL's
// tolerances are set tight enough to meet it (LMA eps 1e-12 on its squared weighted error,
// NR_JL eps 1e-9); spar's solutions reproduce the pose to ~1e-12.
constexpr double kSolvedTolerance = 1e-6;

// How one solver did on the poses: how many it solved and the mean time per pose, failures
// included.
struct IkScore {
  std::string solver;
  int solved{0};
  double seconds{0.0};
};

double pose_residual(const spar::kinematics::RobotModel& robot, const std::vector<double>& q,
                     const Transform& pose) {
  return (robot.forward(q).matrix() - pose.matrix()).cwiseAbs().maxCoeff();
}

// KDL's answer as an in-limit joint vector (its solvers may return an angle 2 pi away from the
// in-limit one, which is the same pose), or false.
bool kdl_answer_within_limits(const spar::kinematics::RobotModel& robot, const KDL::JntArray& out,
                              std::vector<double>& q) {
  q.assign(robot.dof(), 0.0);
  for (std::size_t j = 0; j < robot.dof(); ++j) {
    const spar::kinematics::JointLimits& limits = robot.joints()[j].limits;
    double value = out(static_cast<unsigned>(j));
    if (!std::isfinite(value)) return false;
    value = spar::kinematics::wrap_angle(value);
    while (value < limits.lower - 1e-9) value += 2 * std::numbers::pi;
    if (value > limits.upper + 1e-9) return false;
    q[j] = value;
  }
  return true;
}

// Random restarts within the limits until a solution or the time budget per pose runs out (as
// TRAC-IK's authors ran KDL: "KDL-RR", 5 ms).
template <typename Solve>
IkScore kdl_with_restarts(const char* name, const spar::kinematics::RobotModel& robot,
                          const std::vector<Transform>& poses, double budget, Solve&& solve) {
  std::mt19937_64 random(77);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  KDL::JntArray seed(static_cast<unsigned>(robot.dof())), out(static_cast<unsigned>(robot.dof()));
  std::vector<double> q;
  IkScore score{name, 0, 0.0};
  const Clock::time_point start = Clock::now();
  for (const Transform& pose : poses) {
    const KDL::Frame target = kdl_frame(pose);
    const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                          std::chrono::duration<double>(budget));
    while (Clock::now() < deadline) {
      for (std::size_t j = 0; j < robot.dof(); ++j) {
        const spar::kinematics::JointLimits& limits = robot.joints()[j].limits;
        seed(static_cast<unsigned>(j)) =
            limits.lower + (limits.upper - limits.lower) * unit(random);
      }
      if (solve(seed, target, out) >= 0 && kdl_answer_within_limits(robot, out, q) &&
          pose_residual(robot, q, pose) < kSolvedTolerance) {
        ++score.solved;
        break;
      }
    }
  }
  score.seconds = std::chrono::duration<double>(Clock::now() - start).count() / poses.size();
  return score;
}

template <typename Solve>
IkScore spar_solver(const char* name, const spar::kinematics::RobotModel& robot,
                    const std::vector<Transform>& poses, Solve&& solve) {
  IkScore score{name, 0, 0.0};
  const Clock::time_point start = Clock::now();
  for (const Transform& pose : poses) {
    for (const spar::kinematics::JointSolution& solution : solve(pose)) {
      if (solution.within_limits && pose_residual(robot, solution.q, pose) < kSolvedTolerance) {
        ++score.solved;
        break;
      }
    }
  }
  score.seconds = std::chrono::duration<double>(Clock::now() - start).count() / poses.size();
  return score;
}

// UR5 and Panda: spar's closed forms and its numeric solver against KDL's LMA and NR-JL (chains
// read from the same URDF by kdl_parser) on the same random reachable poses.
void run_robot_ik(const BenchOptions& options) {
  const int count = options.quick ? 1000 : 10000;
  const double kdl_budget = 5e-3;
  std::printf(
      "\nIK on %d random reachable poses (q uniform within limits); solved = an in-limit "
      "joint vector reproducing the pose to %.0e\n",
      count, kSolvedTolerance);
  std::printf("%-6s %-44s %9s %12s %8s\n", "robot", "solver", "solved", "us/solve", "vs spar");
  for (const char* name : {"ur5", "panda"}) {
    const spar::kinematics::RobotModel& robot = spar::kinematics::builtin_robot_model(name);
    KDL::Tree tree;
    if (!kdl_parser::treeFromFile(robot.source(), tree)) {
      std::printf("%s: kdl_parser could not read %s\n", name, robot.source().c_str());
      continue;
    }
    KDL::Chain chain;
    tree.getChain(robot.base_link(), robot.tip_link(), chain);
    std::mt19937_64 random(2323);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Transform> poses;
    double fk_disagreement = 0.0;
    KDL::ChainFkSolverPos_recursive kdl_fk(chain);
    for (int i = 0; i < count; ++i) {
      std::vector<double> q;
      KDL::JntArray kdl_q(static_cast<unsigned>(robot.dof()));
      for (std::size_t j = 0; j < robot.dof(); ++j) {
        const spar::kinematics::JointLimits& limits = robot.joints()[j].limits;
        q.push_back(limits.lower + (limits.upper - limits.lower) * unit(random));
        kdl_q(static_cast<unsigned>(j)) = q.back();
      }
      poses.push_back(robot.forward(q));
      KDL::Frame frame;
      kdl_fk.JntToCart(kdl_q, frame);
      fk_disagreement = std::max(fk_disagreement, frame_disagreement(frame, poses.back()));
    }
    KDL::JntArray lower(chain.getNrOfJoints()), upper(chain.getNrOfJoints());
    for (std::size_t j = 0; j < robot.dof(); ++j) {
      lower(static_cast<unsigned>(j)) = robot.joints()[j].limits.lower;
      upper(static_cast<unsigned>(j)) = robot.joints()[j].limits.upper;
    }
    KDL::ChainIkSolverPos_LMA lma(chain, 1e-12);
    KDL::ChainIkSolverVel_pinv velocity(chain);
    KDL::ChainIkSolverPos_NR_JL nr_jl(chain, lower, upper, kdl_fk, velocity, 100, 1e-9);
    std::vector<IkScore> scores;
    scores.push_back(
        spar_solver(std::string(spar::kinematics::to_string(robot.ik_method())).c_str(), robot,
                    poses, [&](const Transform& pose) { return robot.inverse(pose); }));
    scores.back().solver = "spar " + std::string(spar::kinematics::to_string(robot.ik_method()));
    scores.push_back(
        spar_solver("spar numeric (LM, 64 restarts)", robot, poses, [&](const Transform& pose) {
          return robot.inverse_numeric(pose, {.numeric_solutions = 1});
        }));
    scores.push_back(
        kdl_with_restarts("KDL LMA, restarts <= 5 ms", robot, poses, kdl_budget,
                          [&](const KDL::JntArray& seed, const KDL::Frame& target,
                              KDL::JntArray& out) { return lma.CartToJnt(seed, target, out); }));
    scores.push_back(
        kdl_with_restarts("KDL NR_JL, restarts <= 5 ms", robot, poses, kdl_budget,
                          [&](const KDL::JntArray& seed, const KDL::Frame& target,
                              KDL::JntArray& out) { return nr_jl.CartToJnt(seed, target, out); }));
    std::printf("(%s: max |FK spar - FK KDL| = %.1e)\n", name, fk_disagreement);
    for (const IkScore& score : scores)
      std::printf("%-6s %-44s %8.2f%% %12.1f %8.2f\n", name, score.solver.c_str(),
                  100.0 * score.solved / count, score.seconds * 1e6,
                  score.seconds / scores.front().seconds);
    for (std::size_t i = 2; i < scores.size(); ++i)
      std::printf("ratio ik_%s %s %.2f (success %.2f%% vs spar %.2f%%)\n", name,
                  i == 2 ? "kdl_lma" : "kdl_nr_jl", scores[i].seconds / scores.front().seconds,
                  100.0 * scores[i].solved / count, 100.0 * scores.front().solved / count);
  }
}

}  // namespace

int main(int argc, char** argv) {
  BenchOptions options;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      options.quick = true;
    } else {
      std::fprintf(stderr, "usage: %s [--quick]\n", argv[0]);
      return 2;
    }
  }
  std::printf("kinematics benchmark (%s)\n\n", options.quick ? "quick" : "full");
  run_numeric_kinematics(options);
  run_robot_ik(options);
  // The symbolic kinematics (pickup-precondition timing) gets its own function, called here.
  run_pickup_preconditions(options);
  return 0;
}

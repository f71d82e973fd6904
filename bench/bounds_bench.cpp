// bounds: naive interval arithmetic, each bounding stage, and the full pipeline on the FPBench
// corpus, against the reference interval branch and bound's box evaluations (bb_evals, Python,
// recorded in the corpus file), and plain interval tape evaluation against MPFI (53-bit, the
// same tape and boxes, in the same run). Then reuse: one compiled BoundProblem (ConditionSet)
// bounding 1000 boxes against a fresh bound() per box, same boxes, same run, same results checked.
// Usage: bounds_bench [--quick] [--per-record]
#include <mpfi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bounds/bound.hpp"
#include "bounds/condition_set.hpp"
#include "symbolic/parse.hpp"
#include "symbolic/tape.hpp"

using spar::bounds::BoundOptions;
using spar::bounds::BoundResult;
using spar::bounds::BoundStatus;
using spar::bounds::Constraint;
using spar::bounds::Interval;
using spar::bounds::Relation;
namespace symbolic = spar::symbolic;

namespace {

struct Method {
  const char* name;
  BoundOptions options;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool same(const BoundResult& a, const BoundResult& b) {
  return a.lo == b.lo && a.hi == b.hi && a.inner_lo == b.inner_lo && a.inner_hi == b.inner_hi &&
         a.argmin == b.argmin && a.argmax == b.argmax && a.status == b.status &&
         a.evaluations == b.evaluations;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

Relation relation_of(const std::string& text) {
  if (text == "<") return Relation::kLess;
  if (text == "<=") return Relation::kLessEqual;
  if (text == ">") return Relation::kGreater;
  return Relation::kGreaterEqual;
}

// The tape evaluated with MPFI intervals at double precision: the peer of our Interval tape.
// Tapes using pow with a non-integer exponent, min or max are skipped (no MPFI kernel).
class MpfiTape {
 public:
  static std::optional<MpfiTape> compile(const symbolic::Tape& tape) {
    using symbolic::TapeOp;
    for (const symbolic::Instruction& in : tape.instructions()) {
      if (in.op == TapeOp::kPow || in.op == TapeOp::kMin || in.op == TapeOp::kMax) {
        return std::nullopt;
      }
    }
    return MpfiTape(tape);
  }
  MpfiTape(const MpfiTape&) = delete;
  MpfiTape(MpfiTape&& other) noexcept : tape_(other.tape_), slots_(std::move(other.slots_)) {
    other.slots_.clear();
  }
  ~MpfiTape() {
    for (auto& slot : slots_) mpfi_clear(slot.v);
  }

  void evaluate(const std::vector<Interval>& box) {
    using symbolic::TapeOp;
    for (std::size_t i = 0; i < tape_->input_count(); ++i) {
      mpfi_interv_d(slots_[i].v, box[i].lo, box[i].hi);
    }
    for (const symbolic::Instruction& in : tape_->instructions()) {
      mpfi_ptr d = slots_[in.dst].v;
      mpfi_srcptr a = slots_[in.a].v;
      mpfi_srcptr b = slots_[in.b].v;
      switch (in.op) {
        case TapeOp::kAdd:
          mpfi_add(d, a, b);
          break;
        case TapeOp::kSub:
          mpfi_sub(d, a, b);
          break;
        case TapeOp::kMul:
          mpfi_mul(d, a, b);
          break;
        case TapeOp::kDiv:
          mpfi_div(d, a, b);
          break;
        case TapeOp::kNeg:
          mpfi_neg(d, a);
          break;
        case TapeOp::kSquare:
          mpfi_sqr(d, a);
          break;
        case TapeOp::kPowInt:
          power(d, a, in.power);
          break;
        case TapeOp::kSqrt:
          mpfi_sqrt(d, a);
          break;
        case TapeOp::kSin:
          mpfi_sin(d, a);
          break;
        case TapeOp::kCos:
          mpfi_cos(d, a);
          break;
        case TapeOp::kTan:
          mpfi_tan(d, a);
          break;
        case TapeOp::kExp:
          mpfi_exp(d, a);
          break;
        case TapeOp::kLog:
          mpfi_log(d, a);
          break;
        case TapeOp::kAbs:
          mpfi_abs(d, a);
          break;
        case TapeOp::kAtan:
          mpfi_atan(d, a);
          break;
        case TapeOp::kAsin:
          mpfi_asin(d, a);
          break;
        case TapeOp::kAcos:
          mpfi_acos(d, a);
          break;
        case TapeOp::kAtan2:
          mpfi_atan2(d, a, b);
          break;
        default:
          break;  // excluded by compile()
      }
    }
  }

 private:
  struct Slot {
    mpfi_t v;
  };
  explicit MpfiTape(const symbolic::Tape& tape) : tape_(&tape), slots_(tape.slot_count()) {
    for (auto& slot : slots_) mpfi_init2(slot.v, 53);
    const auto constants = tape.constants();
    for (std::size_t i = 0; i < constants.size(); ++i) {
      const Interval c = spar::bounds::enclose(constants[i]);
      mpfi_interv_d(slots_[tape.input_count() + i].v, c.lo, c.hi);
    }
  }
  // x^n by binary powering (MPFI has no integer power); n < 0 inverts.
  void power(mpfi_ptr d, mpfi_srcptr a, int n) {
    mpfi_t base, result;
    mpfi_init2(base, 53);
    mpfi_init2(result, 53);
    mpfi_set(base, a);
    mpfi_set_d(result, 1.0);
    for (unsigned k = n < 0 ? -static_cast<unsigned>(n) : n; k; k >>= 1) {
      if (k & 1) mpfi_mul(result, result, base);
      mpfi_sqr(base, base);
    }
    if (n < 0) {
      mpfi_inv(d, result);
    } else {
      mpfi_set(d, result);
    }
    mpfi_clear(base);
    mpfi_clear(result);
  }
  const symbolic::Tape* tape_;
  std::vector<Slot> slots_;
};

}  // namespace

// A deterministic stream of numbers in [0, 1) (the boxes must be the same in every run).
struct Lcg {
  std::uint64_t state{20261201};
  double next() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  }
};

// A pickup precondition's shape (kinematics/pickup.hpp): half the finger opening plus the contact's
// y in the gripper frame, cos Δθ_g (q_y - Δy_g) - sin Δθ_g (q_x - Δx_g), with q the contact point
// displaced by the object's uncertainty (Δx_o, Δy_o, Δθ_o), the object turned 30 degrees.
std::string pickup_like(const char* half_opening, const char* half_width) {
  const std::string w = half_width;
  const std::string qx = "(0.866*dxo + 0.5*dyo - " + w + "*sin(tho + 0.5236))";
  const std::string qy = "(-0.5*dxo + 0.866*dyo + " + w + "*cos(tho + 0.5236))";
  return std::string(half_opening) + " + cos(tg)*(" + qy + " - dyg) - sin(tg)*(" + qx + " - dxg)";
}

struct ReuseTimes {
  double fresh{0}, reused{0};         // seconds in all
  std::vector<double> per_box_ratio;  // fresh / reused, box by box
  std::size_t boxes{0}, different{0};
  void add(const ReuseTimes& other) {
    fresh += other.fresh;
    reused += other.reused;
    per_box_ratio.insert(per_box_ratio.end(), other.per_box_ratio.begin(),
                         other.per_box_ratio.end());
    boxes += other.boxes;
    different += other.different;
  }
};

// Bounds f over every box twice, interleaved box by box (so a busy machine slows both alike): a
// fresh bound() (compiles f's tape, checks the box) and one BoundProblem reused for all boxes.
ReuseTimes time_reuse(symbolic::Expr f, const std::vector<symbolic::Expr>& variables,
                      const std::vector<std::vector<Interval>>& boxes,
                      std::span<const Constraint> constraints, const BoundOptions& options) {
  ReuseTimes times;
  auto start = std::chrono::steady_clock::now();
  spar::bounds::BoundProblem problem(f, variables, constraints);
  times.reused = seconds_since(start);
  for (const std::vector<Interval>& ranges : boxes) {
    start = std::chrono::steady_clock::now();
    spar::bounds::Box box;
    for (std::size_t i = 0; i < variables.size(); ++i) {
      box.add(variables[i], ranges[i].lo, ranges[i].hi);
    }
    const BoundResult fresh = spar::bounds::bound(f, box, options, constraints);
    const double fresh_seconds = seconds_since(start);
    start = std::chrono::steady_clock::now();
    const BoundResult reused = problem.bound(ranges, options);
    const double reused_seconds = seconds_since(start);
    times.fresh += fresh_seconds;
    times.reused += reused_seconds;
    times.per_box_ratio.push_back(fresh_seconds / reused_seconds);
    times.different += same(fresh, reused) ? 0 : 1;
  }
  times.boxes = boxes.size();
  return times;
}

void print_reuse(const char* workload, const ReuseTimes& t) {
  std::printf(
      "%-30s %5zu boxes  fresh %8.1f us/box  reused %8.1f us/box  per-box ratio median %.3g  "
      "different %zu\n",
      workload, t.boxes, 1e6 * t.fresh / t.boxes, 1e6 * t.reused / t.boxes, median(t.per_box_ratio),
      t.different);
}

// Reuse over 1000 boxes: what phase 2 does when it widens, senses or bisects.
void run_reuse(const std::vector<nlohmann::json>& records, bool quick) {
  const std::size_t box_count = 1000;
  const BoundOptions options{};  // the defaults: a work budget, no clock
  std::printf("\nreuse: one compiled problem over %zu boxes vs a fresh bound() per box\n",
              box_count);
  // 1. The pickup-like inequality over a widening of the object's uncertainty (0.02 to 0.6).
  symbolic::ExprPool pool;
  std::vector<symbolic::Expr> variables;
  for (const char* name : {"dxg", "dyg", "tg", "dxo", "dyo", "tho"}) {
    variables.push_back(pool.variable(name));
  }
  std::vector<std::vector<Interval>> widening;
  for (std::size_t b = 0; b < box_count; ++b) {
    const double w = 0.02 + 0.58 * static_cast<double>(b) / (box_count - 1);
    widening.push_back(
        {{-1e-3, 1e-3}, {-1e-3, 1e-3}, {-1e-3, 1e-3}, {-w, w}, {-w, w}, {-0.096, 0.096}});
  }
  const symbolic::Expr y = symbolic::parse(pool, pickup_like("2", "1.5"));
  const ReuseTimes pickup = time_reuse(y, variables, widening, {}, options);
  print_reuse("pickup-like inequality, widening", pickup);
  // 2. The same four pickup inequalities as one ConditionSet vs a fresh bound() of each.
  const std::vector<spar::bounds::Inequality> inequalities{
      {"P1.C1", y, Relation::kGreater, 0.0},
      {"P1.C2", symbolic::parse(pool, pickup_like("2", "-1.5")), Relation::kGreater, 0.0},
      {"P2.C1", symbolic::parse(pool, pickup_like("-2", "1.5")), Relation::kLess, 0.0},
      {"P2.C2", symbolic::parse(pool, pickup_like("-2", "-1.5")), Relation::kLess, 0.0}};
  ReuseTimes set_times;
  std::size_t escalated = 0;
  {
    spar::bounds::ConditionSet set(inequalities, variables);
    for (const auto& ranges : widening) {
      auto start = std::chrono::steady_clock::now();
      spar::bounds::Box box;
      for (std::size_t i = 0; i < variables.size(); ++i) {
        box.add(variables[i], ranges[i].lo, ranges[i].hi);
      }
      std::vector<spar::bounds::Verdict> fresh;
      for (const auto& q : inequalities) {
        fresh.push_back(decide(q, spar::bounds::bound(q.expression, box, options)));
      }
      const double fresh_seconds = seconds_since(start);
      start = std::chrono::steady_clock::now();
      const std::vector<spar::bounds::ConditionCheck> checks = set.check(ranges, options);
      const double reused_seconds = seconds_since(start);
      set_times.fresh += fresh_seconds;
      set_times.reused += reused_seconds;
      set_times.per_box_ratio.push_back(fresh_seconds / reused_seconds);
      for (std::size_t k = 0; k < checks.size(); ++k) {
        set_times.different += checks[k].verdict != fresh[k] ? 1 : 0;
        escalated += checks[k].escalated ? 1 : 0;
      }
    }
    set_times.boxes = widening.size();
  }
  print_reuse("4 pickup-like, ConditionSet", set_times);
  std::printf("  (verdicts compared; %zu of %zu inequality checks escalated to a full bound)\n",
              escalated, 4 * widening.size());
  // 3. FPBench: sub-boxes of every bounded record (constraints included), 1000 in all.
  Lcg random;
  ReuseTimes corpus;
  std::size_t bounded = 0;
  for (const auto& record : records) bounded += record.value("range_unbounded", false) ? 0 : 1;
  const std::size_t per_record = std::max<std::size_t>(1, box_count / bounded);
  for (const auto& record : records) {
    if (record.value("range_unbounded", false)) continue;
    if (quick && corpus.boxes >= box_count / 4) break;
    symbolic::ExprPool record_pool;
    std::vector<symbolic::Expr> record_variables;
    std::vector<Interval> root;
    for (const auto& [var, range] : record["vars"].items()) {
      record_variables.push_back(record_pool.variable(var));
      root.push_back({range[0].get<double>(), range[1].get<double>()});
    }
    std::vector<Constraint> constraints;
    for (const auto& c : record.value("constraints", nlohmann::json::array())) {
      constraints.push_back({symbolic::parse(record_pool, c["g"].get<std::string>()),
                             relation_of(c["rel"].get<std::string>())});
    }
    std::vector<std::vector<Interval>> boxes;
    for (std::size_t b = 0; b < per_record; ++b) {
      std::vector<Interval> box;
      for (const Interval& r : root) {
        const double centre = r.lo + (r.hi - r.lo) * random.next();
        const double half = (r.hi - r.lo) * random.next() / 2;
        box.push_back({std::max(r.lo, centre - half), std::min(r.hi, centre + half)});
      }
      boxes.push_back(std::move(box));
    }
    const symbolic::Expr f = symbolic::parse(record_pool, record["expr"].get<std::string>());
    corpus.add(time_reuse(f, record_variables, boxes, constraints, options));
  }
  print_reuse("FPBench sub-boxes", corpus);
  // Medians of the per-box ratios: robust to a busy machine (the totals are printed above).
  std::printf("ratio bound_problem_reuse(pickup_like,median_per_box) fresh_bound %.3g\n",
              median(pickup.per_box_ratio));
  std::printf("ratio condition_set(4_pickup_like,median_per_box) fresh_bound_each %.3g\n",
              median(set_times.per_box_ratio));
  std::printf("ratio bound_problem_reuse(fpbench_subboxes,median_per_box) fresh_bound %.3g\n",
              median(corpus.per_box_ratio));
}

// Large inputs (issue 12): the effort limit holds in proportion to the input, memory stays
// linear. Parse + bound with the default options; prints time and boxes.
void run_large(bool quick) {
  std::printf("\nlarge inputs (default options: work budget, no clock)\n");
  const auto run = [](const char* label, const std::string& text, int variables) {
    symbolic::ExprPool pool;
    const auto start = std::chrono::steady_clock::now();
    const symbolic::Expr f = symbolic::parse(pool, text);
    const double parse_seconds = seconds_since(start);
    spar::bounds::Box box;
    if (variables == 1) {
      box.add(pool.variable("x"), -1, 1);
    } else {
      for (int i = 0; i < variables; ++i) {
        std::string name = "v";
        name += std::to_string(i);
        box.add(pool.variable(name), -1, 1);
      }
    }
    const auto bound_start = std::chrono::steady_clock::now();
    const BoundResult r = spar::bounds::bound(f, box);
    std::printf("%-34s parse %7.3f s  bound %7.3f s  %zu boxes  %s  [%.6g, %.6g]\n", label,
                parse_seconds, seconds_since(bound_start), r.evaluations,
                spar::bounds::to_string(r.status), r.lo, r.hi);
  };
  std::string sum = "v0";
  for (int i = 1; i < 2000; ++i) {
    sum += " + v";
    sum += std::to_string(i);
  }
  run("sum of 2000 variables", sum, 2000);
  const int terms = quick ? 10000 : 100000;
  std::string sines = "sin(x)";
  for (int i = 1; i < terms; ++i) {
    sines += " + sin(x + ";
    sines += std::to_string(i);
    sines += ')';
  }
  run(quick ? "10k terms sin(x + i)" : "100k terms sin(x + i)", sines, 1);
}

int main(int argc, char** argv) {
  bool quick = false, per_record = false;
  for (int i = 1; i < argc; ++i) {
    quick = quick || std::strcmp(argv[i], "--quick") == 0;
    per_record = per_record || std::strcmp(argv[i], "--per-record") == 0;
  }
  // Each stage alone (no SMP rewrite, which `bound` otherwise tries after an effort limit), then
  // the full pipeline with the defaults.
  const std::vector<Method> methods = {
      {"naive",
       {.inner = false,
        .monotonicity = false,
        .centred_form = false,
        .branch_and_bound = false,
        .simplify = false}},
      {"monotone",
       {.inner = false,
        .monotonicity = true,
        .centred_form = false,
        .branch_and_bound = false,
        .simplify = false}},
      {"centred",
       {.inner = false,
        .monotonicity = false,
        .centred_form = true,
        .branch_and_bound = false,
        .simplify = false}},
      {"bb_natural",
       {.inner = true, .monotonicity = false, .centred_form = false, .simplify = false}},
      {"full", {}},
  };

  std::ifstream in(std::string(SPAR_CORPUS_DIR) + "/fpbench.jsonl");
  if (!in) {
    std::fprintf(stderr, "cannot open corpus\n");
    return 1;
  }
  std::vector<nlohmann::json> records;
  for (std::string line; std::getline(in, line);) records.push_back(nlohmann::json::parse(line));

  std::vector<std::vector<double>> ratios(methods.size()), times(methods.size());
  std::vector<std::size_t> converged(methods.size(), 0);
  std::vector<double> eval_ratios;
  std::size_t fewer_evals = 0, no_more_evals = 0, bounded = 0, instructions = 0;
  double interval_ns = 0, mpfi_ns_total = 0, our_ns_on_mpfi_records = 0;
  std::size_t mpfi_records = 0, mpfi_instructions = 0;
  std::vector<double> gaps;  // full pipeline: max(hi - inner_hi, inner_lo - lo) / width
  std::vector<std::string> not_converged;
  const int repeats = quick ? 1 : 3;
  if (per_record)
    std::printf("%-40s %10s %10s %9s %9s %10s %8s\n", "record", "naive", "full", "evals",
                "ref_evals", "time_us", "status");
  for (const auto& record : records) {
    symbolic::ExprPool pool;
    spar::bounds::Box box;
    for (const auto& [var, range] : record["vars"].items()) {
      box.add(pool.variable(var), range[0].get<double>(), range[1].get<double>());
    }
    const symbolic::Expr f = symbolic::parse(pool, record["expr"].get<std::string>());
    std::vector<Constraint> constraints;
    for (const auto& c : record.value("constraints", nlohmann::json::array())) {
      constraints.push_back({symbolic::parse(pool, c["g"].get<std::string>()),
                             relation_of(c["rel"].get<std::string>())});
    }
    const bool unbounded = record.value("range_unbounded", false);
    const double width = record["ref_max"].get<double>() - record["ref_min"].get<double>();
    // Plain interval arithmetic on the tape (ns per instruction), and MPFI on the same tape.
    {
      const symbolic::Tape tape = symbolic::Tape::compile(std::array{f}, box.variables);
      symbolic::TapeEvaluator<Interval> evaluator(tape);
      Interval out[1];
      const int loops = 2000;
      const auto timed = [&](auto&& evaluate) {
        const auto start = std::chrono::steady_clock::now();
        for (int k = 0; k < loops; ++k) evaluate();
        return std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start)
                   .count() /
               loops;
      };
      const double ns = timed([&] { evaluator.evaluate(box.ranges, out); });
      interval_ns += ns;
      instructions += tape.instructions().size();
      if (auto peer = MpfiTape::compile(tape)) {
        mpfi_ns_total += timed([&] { peer->evaluate(box.ranges); });
        our_ns_on_mpfi_records += ns;
        ++mpfi_records;
        mpfi_instructions += tape.instructions().size();
      }
    }
    if (unbounded) continue;
    ++bounded;
    BoundResult full_result;
    double full_time = 0, naive_ratio = 0;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      BoundResult r;
      double best = 1e300;
      for (int k = 0; k < repeats; ++k) {
        const auto start = std::chrono::steady_clock::now();
        r = spar::bounds::bound(f, box, methods[m].options, constraints);
        best = std::min(best, std::chrono::duration<double, std::micro>(
                                  std::chrono::steady_clock::now() - start)
                                  .count());
      }
      const double ratio = width > 0 ? (r.hi - r.lo) / width : NAN;
      ratios[m].push_back(ratio);
      times[m].push_back(best);
      if (r.status == BoundStatus::kConverged && methods[m].options.branch_and_bound) {
        ++converged[m];
      }
      if (m == 0) naive_ratio = ratio;
      if (m + 1 == methods.size()) {
        full_result = r;
        full_time = best;
      }
    }
    gaps.push_back(full_result.relative_gap());
    if (full_result.status != BoundStatus::kConverged) {
      not_converged.push_back(record["name"].get<std::string>() + " (" +
                              spar::bounds::to_string(full_result.status) + ")");
    }
    const double reference_evals = record["bb_evals"].get<double>();
    eval_ratios.push_back(reference_evals / std::max<double>(1, full_result.evaluations));
    if (full_result.evaluations < reference_evals) ++fewer_evals;
    if (full_result.evaluations <= reference_evals) ++no_more_evals;
    if (per_record) {
      std::printf("%-40.40s %10.4g %10.6g %9zu %9.0f %10.0f %8s\n",
                  record["name"].get<std::string>().c_str(), naive_ratio, ratios.back().back(),
                  full_result.evaluations, reference_evals, full_time,
                  spar::bounds::to_string(full_result.status));
    }
  }
  std::printf("\n%-12s %14s %16s %14s %10s\n", "method", "median_ratio", "converged(0.1%)",
              "median_us", "max_us");
  for (std::size_t m = 0; m < methods.size(); ++m) {
    std::printf("%-12s %14.6g %11zu/%zu %14.1f %10.0f\n", methods[m].name, median(ratios[m]),
                converged[m], bounded, median(times[m]),
                *std::max_element(times[m].begin(), times[m].end()));
  }
  std::printf(
      "\nfull pipeline: fewer box evaluations than the reference on %zu/%zu records, "
      "no more on %zu/%zu (2, one box per direction, is the least possible)\n",
      fewer_evals, bounded, no_more_evals, bounded);
  std::printf(
      "full pipeline tightness (outer vs inner, relative to the attained width): "
      "median %.3g, max %.3g\n",
      median(gaps), *std::max_element(gaps.begin(), gaps.end()));
  for (const std::string& name : not_converged) std::printf("not converged: %s\n", name.c_str());
  std::printf("interval tape evaluation: %.2f ns per instruction (MPFI on %zu records: %.2f)\n",
              interval_ns / instructions, mpfi_records, mpfi_ns_total / mpfi_instructions);
  // Time ratio, same run, same tapes and boxes.
  std::printf("ratio interval_tape_eval mpfi %.3g\n", mpfi_ns_total / our_ns_on_mpfi_records);
  // Not times: box-evaluation counts (the reference's are from the corpus file) and widths.
  std::printf("ratio fpbench_box_evals(count,median) python_interval_bb %.3g\n",
              median(eval_ratios));
  std::printf("ratio fpbench_width(median) naive_interval %.3g\n",
              median(ratios[0]) / median(ratios.back()));
  run_reuse(records, quick);
  run_large(quick);
  return 0;
}

// bounds: naive interval arithmetic, each bounding stage, and the full pipeline on the FPBench
// corpus, against the reference interval branch and bound's box evaluations (bb_evals, Python,
// recorded in the corpus file), and plain interval tape evaluation against MPFI (53-bit, the
// same tape and boxes, in the same run). Then reuse: one compiled BoundProblem (ConditionSet)
// bounding 1000 boxes against a fresh bound() per box, same boxes, same run, same results checked.
// Gappa (the interval prover, Debian `gappa`) as a peer on the records it reads (+ - * / sqrt, no
// constraints): each record is translated to a Gappa goal `EXPR in ?` under its box and run with
// growing bisection hints; its enclosure and time are set against spar's on the same record, and
// Gappa's start-up on a trivial goal is timed apart. Skipped, with a note, if gappa is missing.
// Usage: bounds_bench [--quick] [--per-record] [--tol T] [--no-gappa] [--gappa-only]
//                     [--record NAME]   (only the corpus records named NAME)
//   --tol T: the full pipeline's tolerance (default 1e-3, the corpus test's; 5e-4 puts the whole
//   enclosure within 0.1% of the attained range)
#include <mpfi.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/condition_set.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

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

// 2. The four pickup-like inequalities as one ConditionSet vs a fresh bound() of each, over the
// widening boxes; `escalated` counts the checks that needed a full bound.
ReuseTimes time_condition_set(const std::vector<spar::bounds::Inequality>& inequalities,
                              const std::vector<symbolic::Expr>& variables,
                              const std::vector<std::vector<Interval>>& widening,
                              const BoundOptions& options, std::size_t& escalated) {
  ReuseTimes set_times;
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
  return set_times;
}

// 3. FPBench: random sub-boxes of every bounded record (constraints included), `box_count` in
// all (a quarter with `quick`).
ReuseTimes time_corpus_reuse(const std::vector<nlohmann::json>& records, std::size_t box_count,
                             bool quick, const BoundOptions& options) {
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
  return corpus;
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
  const std::vector<spar::bounds::Inequality> inequalities{
      {"P1.C1", y, Relation::kGreater, 0.0},
      {"P1.C2", symbolic::parse(pool, pickup_like("2", "-1.5")), Relation::kGreater, 0.0},
      {"P2.C1", symbolic::parse(pool, pickup_like("-2", "1.5")), Relation::kLess, 0.0},
      {"P2.C2", symbolic::parse(pool, pickup_like("-2", "-1.5")), Relation::kLess, 0.0}};
  std::size_t escalated = 0;
  const ReuseTimes set_times =
      time_condition_set(inequalities, variables, widening, options, escalated);
  print_reuse("4 pickup-like, ConditionSet", set_times);
  std::printf("  (verdicts compared; %zu of %zu inequality checks escalated to a full bound)\n",
              escalated, 4 * widening.size());
  const ReuseTimes corpus = time_corpus_reuse(records, box_count, quick, options);
  print_reuse("FPBench sub-boxes", corpus);
  // Medians of the per-box ratios: robust to a busy machine (the totals are printed above).
  std::printf("ratio bound_problem_reuse(pickup_like,median_per_box) fresh_bound %.3g\n",
              median(pickup.per_box_ratio));
  std::printf("ratio condition_set(4_pickup_like,median_per_box) fresh_bound_each %.3g\n",
              median(set_times.per_box_ratio));
  std::printf("ratio bound_problem_reuse(fpbench_subboxes,median_per_box) fresh_bound %.3g\n",
              median(corpus.per_box_ratio));
}

// ---- Gappa peer ----------------------------------------------------------------------------

// A double as a Gappa number, exactly: m b e (m · 2^e).
std::string gappa_number(double value) {
  if (value == 0) return "0";
  int exponent = 0;
  const double fraction = std::frexp(value, &exponent);  // value = fraction · 2^exponent
  const auto mantissa = static_cast<long long>(std::ldexp(fraction, 53));
  return std::to_string(mantissa) + "b" + std::to_string(exponent - 53);
}

// The record's expression in Gappa's syntax over variables v0, v1, ... (Gappa's own names could
// clash), or nullopt if Gappa cannot read it: a function other than sqrt, a power, a constraint.
std::optional<std::string> gappa_goal(const nlohmann::json& record) {
  if (record.contains("constraints") && !record["constraints"].empty()) return std::nullopt;
  std::vector<std::string> names;
  std::string ranges;
  for (const auto& [var, range] : record["vars"].items()) {
    if (!ranges.empty()) ranges += " /\\ ";
    ranges += std::string("v") + std::to_string(names.size()) + " in [" +
              gappa_number(range[0].get<double>()) + ", " + gappa_number(range[1].get<double>()) +
              "]";
    names.push_back(var);
  }
  const std::string text = record["expr"].get<std::string>();
  std::string expression;
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t end = i;
      while (end < text.size() &&
             (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_')) {
        ++end;
      }
      const std::string word = text.substr(i, end - i);
      const auto known = std::find(names.begin(), names.end(), word);
      if (known != names.end()) {
        expression += 'v';
        expression += std::to_string(known - names.begin());
      } else if (word == "sqrt") {
        expression += word;
      } else {
        return std::nullopt;  // another function or a named constant
      }
      i = end;
    } else if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      // A decimal literal, exponent included (Gappa reads 1.5e-3 as the exact decimal).
      std::size_t end = i;
      while (end < text.size() &&
             (std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '.')) {
        ++end;
      }
      if (end < text.size() && (text[end] == 'e' || text[end] == 'E')) {
        ++end;
        if (end < text.size() && (text[end] == '+' || text[end] == '-')) ++end;
        while (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) ++end;
      }
      expression += text.substr(i, end - i);
      i = end;
    } else if (std::strchr("+-*/() \t", c) != nullptr) {
      expression += c;
      ++i;
    } else {
      return std::nullopt;  // ^, a comma, ...
    }
  }
  return "{ " + ranges + " -> " + expression + " in ? }\n";
}

// Reads Gappa's number forms: "123b-4" (123 · 2^-4), a decimal, or an integer, to the nearest
// double (Gappa's mantissas may have more than 53 bits): the enclosure is only measured here, and
// rounding it outward would make Gappa look up to two ulps looser than it is.
std::optional<double> parse_gappa_number(const std::string& token) {
  const std::size_t b = token.find('b');
  char* end = nullptr;
  if (b == std::string::npos) {
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str()) return std::nullopt;
    return value;
  }
  const long double mantissa = std::strtold(token.substr(0, b).c_str(), &end);
  const long exponent = std::strtol(token.c_str() + b + 1, nullptr, 10);
  return static_cast<double>(std::ldexp(mantissa, static_cast<int>(exponent)));
}

struct GappaRun {
  bool ok{false};  // Gappa proved an enclosure
  bool timed_out{false};
  double lo{0}, hi{0};
  double seconds{0};  // wall clock of the whole process (start-up included)
};

// Runs gappa on `input` (a file in `dir`) with a time limit; parses "... in [LO {..}, HI {..}]".
GappaRun run_gappa(const std::string& dir, const std::string& input, double limit_seconds) {
  const std::string file = dir + "/goal.g";
  {
    std::ofstream out(file);
    out << input;
  }
  const std::string command =
      std::string("timeout -k 1 ") + std::to_string(limit_seconds) + " gappa " + file + " 2>&1";
  GappaRun run;
  const auto start = std::chrono::steady_clock::now();
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::string output;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    output.append(buffer, n);
  const int status = pclose(pipe);
  run.seconds = seconds_since(start);
  run.timed_out = WIFEXITED(status) && (WEXITSTATUS(status) == 124 || WEXITSTATUS(status) == 137);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return run;
  const std::size_t results = output.find("Results:");
  const std::size_t open = output.find(" in [", results == std::string::npos ? 0 : results);
  if (results == std::string::npos || open == std::string::npos) return run;
  const std::size_t close = output.find(']', open);
  std::string inside = output.substr(open + 5, close - open - 5);
  // Drop the "{decimal, power}" comments.
  std::string bare;
  int depth = 0;
  for (char c : inside) {
    if (c == '{') ++depth;
    if (depth == 0) bare += c;
    if (c == '}') --depth;
  }
  const std::size_t comma = bare.find(',');
  if (comma == std::string::npos) return run;
  const auto trim = [](std::string t) {
    t.erase(0, t.find_first_not_of(' '));
    t.erase(t.find_last_not_of(' ') + 1);
    return t;
  };
  const auto lo = parse_gappa_number(trim(bare.substr(0, comma)));
  const auto hi = parse_gappa_number(trim(bare.substr(comma + 1)));
  if (!lo || !hi) return run;
  run.ok = true;
  run.lo = *lo;
  run.hi = *hi;
  return run;
}

bool gappa_available() { return std::system("gappa --version > /dev/null 2>&1") == 0; }

// spar's full pipeline (at `tolerance`) against Gappa on every record Gappa reads. Gappa runs
// with bisection hints `$ v0 in k, v1 in k, ...` giving at most `pieces` sub-boxes in all, for
// pieces = 1, 16, 256, 4096 (--quick: 1, 64), until a run times out or its enclosure is within
// 0.1% of the true range; its enclosure is the intersection of its runs' (each one proved), its
// time that of the run that gave the last improvement (the hint one would have had to know).
void run_gappa_peer(const std::vector<nlohmann::json>& records, bool quick, double tolerance,
                    bool per_record) {
  std::printf("\ngappa peer: records Gappa reads (+ - * / sqrt, no constraints)\n");
  if (!gappa_available()) {
    std::printf("gappa is not installed (apt-get install gappa): peer skipped\n");
    return;
  }
  char dir_template[] = "/tmp/bounds_bench_gappa_XXXXXX";
  const char* dir = mkdtemp(dir_template);
  if (dir == nullptr) {
    std::printf("cannot make a temporary directory: gappa peer skipped\n");
    return;
  }
  // Start-up: a trivial goal, median of 9 runs.
  std::vector<double> startup;
  for (int k = 0; k < 9; ++k) {
    startup.push_back(run_gappa(dir, "{ x in [0, 1] -> x in ? }\n", 10).seconds);
  }
  const double startup_ms = 1e3 * median(startup);
  std::printf("gappa start-up (trivial goal, median of 9): %.2f ms\n", startup_ms);
  const std::vector<int> schedule =
      quick ? std::vector<int>{1, 64} : std::vector<int>{1, 16, 256, 4096};
  const double limit_seconds = quick ? 2 : 10;
  if (per_record) {
    std::printf("%-32s %5s %12s %12s %10s %10s %7s\n", "record", "vars", "spar/true", "gappa/true",
                "spar_ms", "gappa_ms", "pieces");
  }
  std::size_t read = 0, spar_close = 0, gappa_close = 0, spar_tighter_or_equal = 0, spar_faster = 0,
              gappa_proved = 0;
  std::vector<double> spar_ms, gappa_ms, spar_ratios, gappa_ratios;
  std::vector<std::string> looser;
  for (const auto& record : records) {
    const std::optional<std::string> goal = gappa_goal(record);
    if (!goal || record.value("range_unbounded", false)) continue;
    ++read;
    const double width = record["ref_max"].get<double>() - record["ref_min"].get<double>();
    symbolic::ExprPool pool;
    spar::bounds::Box box;
    for (const auto& [var, range] : record["vars"].items()) {
      box.add(pool.variable(var), range[0].get<double>(), range[1].get<double>());
    }
    const symbolic::Expr f = symbolic::parse(pool, record["expr"].get<std::string>());
    BoundResult r;
    double spar_seconds = 1e300;
    for (int k = 0; k < (quick ? 1 : 3); ++k) {
      const auto start = std::chrono::steady_clock::now();
      r = spar::bounds::bound(f, box, {.tolerance = tolerance});
      spar_seconds = std::min(spar_seconds, seconds_since(start));
    }
    const double spar_ratio = (r.hi - r.lo) / width;
    // Gappa with growing hints.
    double lo = -HUGE_VAL, hi = HUGE_VAL, seconds = 0;
    int pieces_used = 0;
    const std::size_t n = box.variables.size();
    for (int pieces : schedule) {
      const int per_variable =
          std::max(1, static_cast<int>(std::floor(std::pow(pieces, 1.0 / n) + 1e-9)));
      std::string input = *goal;
      if (per_variable > 1) {
        input += "$ ";
        for (std::size_t i = 0; i < n; ++i) {
          input += std::string(i ? ", v" : "v") + std::to_string(i) + " in " +
                   std::to_string(per_variable);
        }
        input += ";\n";
      }
      const GappaRun run = run_gappa(dir, input, limit_seconds);
      if (run.ok && (run.lo > lo || run.hi < hi)) {
        lo = std::max(lo, run.lo);
        hi = std::min(hi, run.hi);
        seconds = run.seconds;
        pieces_used = static_cast<int>(std::pow(per_variable, n));
      }
      if (run.timed_out ||
          (std::isfinite(lo) && std::isfinite(hi) && hi - lo <= (1 + 1e-3) * width)) {
        break;
      }
    }
    const bool proved = std::isfinite(lo) && std::isfinite(hi);
    const double gappa_ratio = proved ? (hi - lo) / width : HUGE_VAL;
    gappa_proved += proved ? 1 : 0;
    spar_close += spar_ratio <= 1 + 1e-3 ? 1 : 0;
    gappa_close += gappa_ratio <= 1 + 1e-3 ? 1 : 0;
    // Ties within rounding (1e-12 of the width) count as ties.
    if (r.hi - r.lo <= (proved ? (hi - lo) * (1 + 1e-12) : HUGE_VAL)) {
      ++spar_tighter_or_equal;
    } else {
      looser.push_back(record["name"].get<std::string>());
    }
    spar_ms.push_back(1e3 * spar_seconds);
    spar_ratios.push_back(spar_ratio);
    gappa_ratios.push_back(gappa_ratio);
    if (proved) {
      gappa_ms.push_back(1e3 * seconds);
      spar_faster += spar_seconds < seconds ? 1 : 0;
    }
    if (per_record) {
      std::printf("%-32.32s %5zu %12.7g %12.7g %10.3f %10.1f %7d\n",
                  record["name"].get<std::string>().c_str(), n, spar_ratio, gappa_ratio,
                  1e3 * spar_seconds, proved ? 1e3 * seconds : NAN, pieces_used);
    }
  }
  std::remove((std::string(dir) + "/goal.g").c_str());
  rmdir(dir);
  std::printf(
      "gappa reads %zu records, proves an enclosure on %zu; within 0.1%% of the true range: spar "
      "%zu/%zu, gappa %zu/%zu\n",
      read, gappa_proved, spar_close, read, gappa_close, read);
  std::printf("spar at least as tight as gappa on %zu/%zu; faster on %zu/%zu\n",
              spar_tighter_or_equal, read, spar_faster, gappa_proved);
  for (const std::string& name : looser) std::printf("spar looser than gappa: %s\n", name.c_str());
  std::printf(
      "median width ratio (enclosure/true): spar %.7g, gappa %.7g; median ms: spar %.3f, gappa "
      "%.1f (start-up %.2f included)\n",
      median(spar_ratios), median(gappa_ratios), median(spar_ms), median(gappa_ms), startup_ms);
  std::printf("ratio fpbench_gappa_records(median_ms) gappa %.3g\n",
              median(gappa_ms) / median(spar_ms));
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

// The command line: --quick, --per-record, --no-gappa, --gappa-only, --tol T, --record NAME.
struct BenchArguments {
  bool quick{false}, per_record{false}, gappa{true}, gappa_only{false};
  double tolerance{BoundOptions{}.tolerance};
  std::string only_record;
};

BenchArguments parse_arguments(int argc, char** argv) {
  BenchArguments out;
  for (int i = 1; i < argc; ++i) {
    out.quick = out.quick || std::strcmp(argv[i], "--quick") == 0;
    out.per_record = out.per_record || std::strcmp(argv[i], "--per-record") == 0;
    out.gappa = out.gappa && std::strcmp(argv[i], "--no-gappa") != 0;
    out.gappa_only = out.gappa_only || std::strcmp(argv[i], "--gappa-only") == 0;
    if (std::strcmp(argv[i], "--tol") == 0 && i + 1 < argc) out.tolerance = std::atof(argv[++i]);
    if (std::strcmp(argv[i], "--record") == 0 && i + 1 < argc) out.only_record = argv[++i];
  }
  return out;
}

// Each stage alone (no SMP rewrite, which `bound` otherwise tries after an effort limit), then
// the full pipeline with the defaults.
std::vector<Method> bound_methods(double tolerance) {
  return {
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
      {"full", {.tolerance = tolerance}},
  };
}

// The corpus records (only the one named `only_record`, unless empty); empty when it has none.
std::vector<nlohmann::json> read_records(const std::string& only_record) {
  std::ifstream in(std::string(SPAR_CORPUS_DIR) + "/fpbench.jsonl");
  if (!in) {
    std::fprintf(stderr, "cannot open corpus\n");
    return {};
  }
  std::vector<nlohmann::json> records;
  for (std::string line; std::getline(in, line);) {
    nlohmann::json record = nlohmann::json::parse(line);
    if (only_record.empty() || record["name"] == only_record) records.push_back(std::move(record));
  }
  if (records.empty()) std::fprintf(stderr, "no corpus record named \"%s\"\n", only_record.c_str());
  return records;
}

// The corpus run of every method: per method the width ratios, times and convergence; the tape
// timings against MPFI; the full pipeline's box evaluations against the reference's.
class CorpusTally {
 public:
  CorpusTally(std::vector<Method> methods, const BenchArguments& arguments)
      : methods_(std::move(methods)),
        arguments_(arguments),
        ratios_(methods_.size()),
        times_(methods_.size()),
        converged_(methods_.size(), 0) {}

  void add(const nlohmann::json& record) {
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
    time_tape(f, box);
    if (record.value("range_unbounded", false)) return;
    ++bounded_;
    bound_with_each_method(record, f, box, constraints);
  }

  void print() const {
    std::printf("\n%-12s %14s %16s %14s %10s\n", "method", "median_ratio", "converged(tol)",
                "median_us", "max_us");
    for (std::size_t m = 0; m < methods_.size(); ++m) {
      std::printf("%-12s %14.6g %11zu/%zu %14.1f %10.0f\n", methods_[m].name, median(ratios_[m]),
                  converged_[m], bounded_, median(times_[m]),
                  *std::max_element(times_[m].begin(), times_[m].end()));
    }
    std::printf(
        "\nfull pipeline: fewer box evaluations than the reference on %zu/%zu records, "
        "no more on %zu/%zu (spar evaluates a box once for both directions, the reference once "
        "per\n"
        "direction: its least is 2, ours 1)\n",
        fewer_evals_, bounded_, no_more_evals_, bounded_);
    std::printf(
        "full pipeline tightness (outer vs inner, relative to the attained width): "
        "median %.3g, max %.3g\n",
        median(gaps_), *std::max_element(gaps_.begin(), gaps_.end()));
    for (const std::string& name : not_converged_) std::printf("not converged: %s\n", name.c_str());
    std::printf("interval tape evaluation: %.2f ns per instruction (MPFI on %zu records: %.2f)\n",
                interval_ns_ / instructions_, mpfi_records_, mpfi_ns_total_ / mpfi_instructions_);
    // Time ratio, same run, same tapes and boxes.
    std::printf("ratio interval_tape_eval mpfi %.3g\n", mpfi_ns_total_ / our_ns_on_mpfi_records_);
    // Not times: box-evaluation counts (the reference's are from the corpus file) and widths.
    std::printf("ratio fpbench_box_evals(count,median) python_interval_bb %.3g\n",
                median(eval_ratios_));
    std::printf("ratio fpbench_width(median) naive_interval %.3g\n",
                median(ratios_[0]) / median(ratios_.back()));
  }

 private:
  // Plain interval arithmetic on the tape (ns per instruction), and MPFI on the same tape.
  void time_tape(symbolic::Expr f, const spar::bounds::Box& box) {
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
    interval_ns_ += ns;
    instructions_ += tape.instructions().size();
    if (auto peer = MpfiTape::compile(tape)) {
      mpfi_ns_total_ += timed([&] { peer->evaluate(box.ranges); });
      our_ns_on_mpfi_records_ += ns;
      ++mpfi_records_;
      mpfi_instructions_ += tape.instructions().size();
    }
  }

  void bound_with_each_method(const nlohmann::json& record, symbolic::Expr f,
                              const spar::bounds::Box& box,
                              const std::vector<Constraint>& constraints) {
    const double width = record["ref_max"].get<double>() - record["ref_min"].get<double>();
    const int repeats = arguments_.quick ? 1 : 3;
    BoundResult full_result;
    double full_time = 0, naive_ratio = 0;
    for (std::size_t m = 0; m < methods_.size(); ++m) {
      BoundResult r;
      double best = 1e300;
      for (int k = 0; k < repeats; ++k) {
        const auto start = std::chrono::steady_clock::now();
        r = spar::bounds::bound(f, box, methods_[m].options, constraints);
        best = std::min(best, std::chrono::duration<double, std::micro>(
                                  std::chrono::steady_clock::now() - start)
                                  .count());
      }
      const double ratio = width > 0 ? (r.hi - r.lo) / width : NAN;
      ratios_[m].push_back(ratio);
      times_[m].push_back(best);
      if (r.status == BoundStatus::kConverged && methods_[m].options.branch_and_bound) {
        ++converged_[m];
      }
      if (m == 0) naive_ratio = ratio;
      if (m + 1 == methods_.size()) {
        full_result = r;
        full_time = best;
      }
    }
    gaps_.push_back(full_result.relative_gap());
    if (full_result.status != BoundStatus::kConverged) {
      not_converged_.push_back(record["name"].get<std::string>() + " (" +
                               spar::bounds::to_string(full_result.status) + ")");
    }
    const double reference_evals = record["bb_evals"].get<double>();
    eval_ratios_.push_back(reference_evals / std::max<double>(1, full_result.evaluations));
    if (full_result.evaluations < reference_evals) ++fewer_evals_;
    if (full_result.evaluations <= reference_evals) ++no_more_evals_;
    if (arguments_.per_record) {
      std::printf("%-40.40s %10.4g %10.6g %9zu %9.0f %10.0f %8s\n",
                  record["name"].get<std::string>().c_str(), naive_ratio, ratios_.back().back(),
                  full_result.evaluations, reference_evals, full_time,
                  spar::bounds::to_string(full_result.status));
    }
  }

  std::vector<Method> methods_;
  BenchArguments arguments_;
  std::vector<std::vector<double>> ratios_, times_;
  std::vector<std::size_t> converged_;
  std::vector<double> eval_ratios_;
  std::size_t fewer_evals_{0}, no_more_evals_{0}, bounded_{0}, instructions_{0};
  double interval_ns_{0}, mpfi_ns_total_{0}, our_ns_on_mpfi_records_{0};
  std::size_t mpfi_records_{0}, mpfi_instructions_{0};
  std::vector<double> gaps_;  // full pipeline: max(hi - inner_hi, inner_lo - lo) / width
  std::vector<std::string> not_converged_;
};

int main(int argc, char** argv) {
  const BenchArguments arguments = parse_arguments(argc, argv);
  const std::vector<nlohmann::json> records = read_records(arguments.only_record);
  if (records.empty()) return 1;
  std::printf("full pipeline tolerance %g\n", arguments.tolerance);
  if (arguments.gappa_only) {
    run_gappa_peer(records, arguments.quick, arguments.tolerance, arguments.per_record);
    return 0;
  }
  if (arguments.per_record)
    std::printf("%-40s %10s %10s %9s %9s %10s %8s\n", "record", "naive", "full", "evals",
                "ref_evals", "time_us", "status");
  CorpusTally tally(bound_methods(arguments.tolerance), arguments);
  for (const auto& record : records) tally.add(record);
  tally.print();
  if (arguments.gappa)
    run_gappa_peer(records, arguments.quick, arguments.tolerance, arguments.per_record);
  run_reuse(records, arguments.quick);
  run_large(arguments.quick);
  return 0;
}

// symbolic benchmark: spar's symbolic core against GiNaC (linked here) and SymPy (a Python script
// written to a temp file and run with /usr/bin/python3), in the same run, on a chain of n uncertain
// homogeneous transforms T_i = Trans(x_i + dx_i, y_i + dy_i, z_i + dz_i) · RotZ(theta_i + dt_i)
// with exact rational nominals (the same numbers, variables and 4×4 products in all three):
//   build     the 16 entries of T_1 ··· T_n (fresh pool / fresh SymPy cache per repetition)
//   jacobian  d(position entries)/d(all 4n Δ variables), chain built untimed beforehand
//   eval      the 12 top entries at 10^5 random points: our Tape + evaluate_batch (and
//             TapeEvaluator<double>), GiNaC subs+evalf per point, SymPy lambdify(cse=True, numpy)
//   deep      a 10 000-deep chain: build (all three), tape evaluation (ours only)
// The peers' expressions are trees (GiNaC and SymPy traverse shared subexpressions once per use),
// so their cost grows like 2^n; every peer workload runs under a time budget (GiNaC in a forked
// child, SymPy under SIGALRM) and, when it cannot finish, its time is estimated from the columns or
// points it did finish (stated next to the number) or given as a lower bound (">").
// Before anything is timed, all three agree on the 12 entries and one Jacobian entry (n = 6, 12) to
// 1e-9, and every value the peers compute later is compared with ours too.
// Prints a table and `ratio <workload> <peer> <peer_time/our_time>` lines. `--quick` < 60 s.
#include <ginac/ginac.h>
#include <signal.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "spar/symbolic/expr.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/tape.hpp"

namespace {

namespace sym = spar::symbolic;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

// Run-time knobs; --quick lowers repetitions and the peers' budgets, never the workloads' sizes
// except the deep chain's number of evaluation points.
struct Config {
  bool quick{false};
  int repetitions{7};
  double peer_budget{5.0};    // seconds of repetitions / columns / points per peer workload
  double peer_timeout{12.0};  // hard limit for one peer workload (a single unit may exceed budget)
  std::size_t points{100000};
  int deep{10000};
  std::size_t deep_points{200};
};

const std::vector<int> kSizes = {6, 12, 24, 48};
constexpr int kBuildRepetitions = 101;  // spar's chain builds per n (see spar_workloads)
// Row-major indices of the 12 entries (rows 0-2) and of the 3 position entries of a 4×4 matrix.
constexpr std::array<int, 12> kEntries = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
constexpr std::array<int, 3> kPosition = {3, 7, 11};

// Exact nominal translation and angle of transform i, as numerator/denominator pairs.
struct Nominal {
  std::int64_t x, xd, y, yd, z, zd, t, td;
};
Nominal nominal(int i) { return {1 + i % 5, 10, i % 3 - 1, 20, i % 2, 25, i % 7 - 3, 8}; }

// Δ value of input `index` at point `point` (of `points`), for chain size n: splitmix64 on a
// counter, uniform in [-0.05, 0.05). The SymPy script computes the same numbers with numpy.
double delta(int n, std::size_t index, std::size_t point, std::size_t points) {
  std::uint64_t z = static_cast<std::uint64_t>(n) * 1000003u + index * points + point;
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53 * 0.1 - 0.05;
}

// Inputs laid out as evaluate_batch wants them: input i at point p is at [i * points + p].
std::vector<double> make_points(int n, std::size_t points) {
  std::vector<double> x(4 * static_cast<std::size_t>(n) * points);
  for (std::size_t i = 0; i < 4 * static_cast<std::size_t>(n); ++i)
    for (std::size_t p = 0; p < points; ++p) x[i * points + p] = delta(n, i, p, points);
  return x;
}

// The chain as a generic 4×4 product over any scalar type (Expr, GiNaC::ex, double), so all
// sides multiply the same matrices in the same order.
template <class S>
using Mat = std::array<S, 16>;

template <class S>
Mat<S> multiply(const Mat<S>& a, const Mat<S>& b) {
  Mat<S> c;
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) {
      S acc = a[r * 4] * b[col];
      for (int k = 1; k < 4; ++k) acc = acc + a[r * 4 + k] * b[k * 4 + col];
      c[r * 4 + col] = acc;
    }
  return c;
}

template <class S, class Var>
struct Chain {
  std::vector<Var> variables;  // dx_0, dy_0, dz_0, dt_0, dx_1, ...
  Mat<S> m;
};

// Builds the chain given the side's constant(num, den), variable(name), sin, cos, 0 and 1.
template <class S, class Var, class Ops>
Chain<S, Var> build_chain(int n, Ops&& ops) {
  Chain<S, Var> chain;
  const S zero = ops.constant(0, 1), one = ops.constant(1, 1);
  for (int i = 0; i < n; ++i) {
    const Nominal nom = nominal(i);
    const std::string suffix = std::to_string(i);
    const Var dx = ops.variable("dx" + suffix), dy = ops.variable("dy" + suffix),
              dz = ops.variable("dz" + suffix), dt = ops.variable("dt" + suffix);
    chain.variables.insert(chain.variables.end(), {dx, dy, dz, dt});
    const S angle = ops.constant(nom.t, nom.td) + dt;
    const S c = ops.cos(angle), s = ops.sin(angle);
    const Mat<S> t = {c,    -s,   zero, ops.constant(nom.x, nom.xd) + dx,
                      s,    c,    zero, ops.constant(nom.y, nom.yd) + dy,
                      zero, zero, one,  ops.constant(nom.z, nom.zd) + dz,
                      zero, zero, zero, one};
    chain.m = i == 0 ? t : multiply(chain.m, t);
  }
  return chain;
}

struct SparOps {
  sym::ExprPool* pool;
  sym::Expr constant(std::int64_t num, std::int64_t den) const {
    return pool->constant(sym::Number::rational(num, den));
  }
  sym::Expr variable(const std::string& name) const { return pool->variable(name); }
  static sym::Expr sin(sym::Expr a) { return sym::sin(a); }
  static sym::Expr cos(sym::Expr a) { return sym::cos(a); }
};
using SparChain = Chain<sym::Expr, sym::Expr>;
SparChain spar_chain(sym::ExprPool& pool, int n) {
  return build_chain<sym::Expr, sym::Expr>(n, SparOps{&pool});
}

struct GinacOps {
  static GiNaC::ex constant(std::int64_t num, std::int64_t den) {
    return GiNaC::numeric(static_cast<long>(num), static_cast<long>(den));
  }
  static GiNaC::symbol variable(const std::string& name) { return GiNaC::symbol(name); }
  static GiNaC::ex sin(const GiNaC::ex& a) { return GiNaC::sin(a); }
  static GiNaC::ex cos(const GiNaC::ex& a) { return GiNaC::cos(a); }
};
using GinacChain = Chain<GiNaC::ex, GiNaC::symbol>;
GinacChain ginac_chain(int n) { return build_chain<GiNaC::ex, GiNaC::symbol>(n, GinacOps{}); }

// Plain double chain at point p: an independent reference for every symbolic result.
std::array<double, 12> reference_values(int n, std::size_t point, std::size_t points) {
  Mat<double> m{};
  for (int i = 0; i < n; ++i) {
    const Nominal nom = nominal(i);
    auto d = [&](int k) { return delta(n, 4 * static_cast<std::size_t>(i) + k, point, points); };
    const double angle = static_cast<double>(nom.t) / nom.td + d(3);
    const double c = std::cos(angle), s = std::sin(angle);
    const Mat<double> t = {c, -s, 0, static_cast<double>(nom.x) / nom.xd + d(0),
                           s, c,  0, static_cast<double>(nom.y) / nom.yd + d(1),
                           0, 0,  1, static_cast<double>(nom.z) / nom.zd + d(2),
                           0, 0,  0, 1};
    m = i == 0 ? t : multiply(m, t);
  }
  std::array<double, 12> out{};
  std::copy_n(m.begin(), 12, out.begin());
  return out;
}

double max_abs_diff(const double* a, const double* b, std::size_t count) {
  double worst = 0;
  for (std::size_t i = 0; i < count; ++i) worst = std::max(worst, std::fabs(a[i] - b[i]));
  return worst;
}

[[noreturn]] void fail(const std::string& message) {
  std::printf("FAIL: %s\n", message.c_str());
  std::exit(1);
}

// ---- running the peers under a time limit -------------------------------------------------

void arm_timer(double seconds) {
  itimerval limit{};
  limit.it_value.tv_sec = static_cast<long>(seconds);
  limit.it_value.tv_usec = static_cast<long>((seconds - std::floor(seconds)) * 1e6);
  setitimer(ITIMER_REAL, &limit, nullptr);  // SIGALRM's default action ends the process
}

// Runs body(emit) in a forked child; returns every double it emitted before it finished or was
// killed (8-byte pipe writes are atomic). The child gets `setup_limit` seconds for its untimed
// set-up; the body calls arm_timer(timeout) once that is done.
template <class Body>
std::vector<double> run_in_child(double setup_limit, Body&& body) {
  std::fflush(stdout);
  int fd[2];
  if (pipe(fd) != 0) fail("pipe");
  const pid_t pid = fork();
  if (pid < 0) fail("fork");
  if (pid == 0) {
    close(fd[0]);
    arm_timer(setup_limit);
    auto emit = [&](double v) {
      if (write(fd[1], &v, sizeof v) != sizeof v) _exit(2);
    };
    body(emit);
    _exit(0);
  }
  close(fd[1]);
  std::vector<double> values;
  double v;
  FILE* in = fdopen(fd[0], "rb");
  while (std::fread(&v, sizeof v, 1, in) == 1) values.push_back(v);
  std::fclose(in);
  waitpid(pid, nullptr, 0);
  return values;
}

// A peer's time for a whole workload: measured (median of complete repetitions), estimated from
// `done` of `total` units, or only known to exceed `seconds`.
struct PeerTime {
  enum class Kind { kMeasured, kEstimated, kLowerBound, kNotRun } kind{Kind::kNotRun};
  double seconds{NAN};
  std::string note;
};

// Units (columns, points, repetitions) finished in the order they ran: `unit_seconds`, `per_rep`
// units make one complete workload, `scale` complete-workload units are the whole workload
// (points: scale = 10^5 / per_rep when the peer evaluates only a sample).
PeerTime summarize(const std::vector<double>& unit_seconds, std::size_t per_rep, double timeout,
                   const char* unit_name) {
  PeerTime t;
  const std::size_t reps = unit_seconds.size() / per_rep;
  if (reps >= 1) {
    std::vector<double> totals;
    for (std::size_t r = 0; r < reps; ++r) {
      double sum = 0;
      for (std::size_t u = 0; u < per_rep; ++u) sum += unit_seconds[r * per_rep + u];
      totals.push_back(sum);
    }
    t.kind = PeerTime::Kind::kMeasured;
    t.seconds = median(totals);
    t.note = "median of " + std::to_string(reps);
  } else if (!unit_seconds.empty()) {
    double sum = 0;
    for (double s : unit_seconds) sum += s;
    t.kind = PeerTime::Kind::kEstimated;
    t.seconds = sum / unit_seconds.size() * per_rep;
    t.note = "est. from " + std::to_string(unit_seconds.size()) + "/" + std::to_string(per_rep) +
             " " + unit_name;
  } else {
    // Not one unit finished in `timeout`: every unit (same tree, other column or point) takes
    // longer, so the whole workload takes more than per_rep × timeout.
    t.kind = PeerTime::Kind::kLowerBound;
    t.seconds = timeout * per_rep;
    char buf[96];
    std::snprintf(buf, sizeof buf, "no %s in %.3g s; x%zu", unit_name, timeout, per_rep);
    t.note = buf;
  }
  return t;
}

// ---- GiNaC workloads (run in children) ----------------------------------------------------

template <class Emit>
void ginac_build(int n, const Config& cfg, Emit&& emit) {
  arm_timer(cfg.peer_timeout);
  double spent = 0;
  for (int rep = 0; rep < cfg.repetitions && spent < cfg.peer_budget; ++rep) {
    const Clock::time_point start = Clock::now();
    const GinacChain chain = ginac_chain(n);
    const double t = seconds_since(start);
    if (chain.m[3].nops() == 0) std::abort();  // consume
    emit(t);
    spent += t;
  }
}

template <class Emit>
void ginac_jacobian(int n, const Config& cfg, Emit&& emit) {
  const GinacChain chain = ginac_chain(n);
  arm_timer(cfg.peer_timeout);
  double spent = 0;
  std::size_t sink = 0;
  for (int rep = 0; rep < cfg.repetitions && spent < cfg.peer_budget; ++rep) {
    for (const GiNaC::symbol& v : chain.variables) {
      const Clock::time_point start = Clock::now();
      for (int e : kPosition) sink += chain.m[e].diff(v).nops();
      const double t = seconds_since(start);
      emit(t);
      spent += t;
      if (spent > cfg.peer_budget && rep == 0) break;
    }
  }
  if (sink == 0xFFFFFFFF) std::abort();
}

// Per point: the time, then the 12 values (so the parent can compare them with ours).
template <class Emit>
void ginac_eval(int n, const Config& cfg, const std::vector<double>& x, Emit&& emit) {
  const GinacChain chain = ginac_chain(n);
  arm_timer(cfg.peer_timeout);
  double spent = 0;
  for (std::size_t p = 0; p < cfg.points && spent < cfg.peer_budget; ++p) {
    const Clock::time_point start = Clock::now();
    GiNaC::exmap values;
    for (std::size_t i = 0; i < chain.variables.size(); ++i)
      values[chain.variables[i]] = GiNaC::numeric(x[i * cfg.points + p]);
    std::array<double, 12> out{};
    for (int e : kEntries)
      out[e] = GiNaC::ex_to<GiNaC::numeric>(
                   chain.m[e].subs(values, GiNaC::subs_options::no_pattern).evalf())
                   .to_double();
    const double t = seconds_since(start);
    emit(t);
    for (double v : out) emit(v);
    spent += t;
  }
}

// ---- the SymPy script -----------------------------------------------------------------------

const char* kSympyScript = R"PY(
import sys, time, signal
import numpy as np
import sympy as sp
from sympy.core.cache import clear_cache

budget, timeout, reps, points, deep = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
sizes = [int(s) for s in sys.argv[6].split(',')]

def nominal(i):
    return (1 + i % 5, 10, i % 3 - 1, 20, i % 2, 25, i % 7 - 3, 8)

M64 = np.uint64(0xFFFFFFFFFFFFFFFF)
def deltas(n, index, pts):
    with np.errstate(over='ignore'):
        z = np.uint64(n * 1000003 + index * pts) + np.arange(pts, dtype=np.uint64)
        z = z + np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) * 2.0**-53 * 0.1 - 0.05

def multiply(a, b):
    c = []
    for r in range(4):
        for col in range(4):
            acc = a[r * 4] * b[col]
            for k in range(1, 4):
                acc = acc + a[r * 4 + k] * b[k * 4 + col]
            c.append(acc)
    return c

def chain(n):
    zero, one = sp.Integer(0), sp.Integer(1)
    variables, m = [], None
    for i in range(n):
        x, xd, y, yd, z, zd, t, td = nominal(i)
        dx, dy, dz, dt = sp.symbols('dx%d dy%d dz%d dt%d' % (i, i, i, i))
        variables += [dx, dy, dz, dt]
        angle = sp.Rational(t, td) + dt
        c, s = sp.cos(angle), sp.sin(angle)
        tr = [c, -s, zero, sp.Rational(x, xd) + dx, s, c, zero, sp.Rational(y, yd) + dy,
              zero, zero, one, sp.Rational(z, zd) + dz, zero, zero, zero, one]
        m = tr if m is None else multiply(m, tr)
    return variables, m

class Timeout(Exception):
    pass
def on_alarm(signum, frame):
    raise Timeout()
signal.signal(signal.SIGALRM, on_alarm)
def out(*args):
    print(*args, flush=True)

def limited(name, n, body, seconds=None):
    signal.setitimer(signal.ITIMER_REAL, seconds or timeout)
    try:
        return body()
    except Timeout:
        out('timeout', name, n)
    except RecursionError:  # SymPy's recursive queries on a deep expression
        out('failed', name, n, 'RecursionError')
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)

# Untimed set-up (building the chain before a Jacobian or an evaluation) gets its own, longer limit.
def setup(name, n):
    return limited('setup_' + name, n, lambda: chain(n), 3 * timeout)

# Cross-check values first (point 0 of 10^5): 12 entries and d m[3] / d dt0.
for n in (6,):
    v, m = chain(n)
    x = [deltas(n, i, points)[:1] for i in range(4 * n)]
    f = sp.lambdify(v, [m[e] for e in range(12)], 'numpy', cse=True)
    vals = [float(np.asarray(r).ravel()[0]) for r in f(*x)]
    j = m[3].diff(v[3]).subs({s: float(xi[0]) for s, xi in zip(v, x)}).evalf(17)
    out('check', n, *['%.17g' % val for val in vals], '%.17g' % float(j))

for n in sizes:
    def build():
        spent, r = 0.0, 0
        while r < reps and spent < budget:
            clear_cache()
            t0 = time.perf_counter(); v, m = chain(n); t = time.perf_counter() - t0
            out('build', n, t); spent += t; r += 1
    limited('build', n, build)
    vm = setup('jac', n)
    def jacobian():
        v, m = vm
        spent = 0.0
        for r in range(reps):
            if spent >= budget: break
            clear_cache()
            for s in v:
                t0 = time.perf_counter(); d = [m[e].diff(s) for e in (3, 7, 11)]; t = time.perf_counter() - t0
                out('jac', n, t); spent += t
                if spent > budget and r == 0: break
    if vm: limited('jac', n, jacobian)
    vm = setup('eval', n)
    def compile():
        v, m = vm
        clear_cache()
        t0 = time.perf_counter()
        f = sp.lambdify(v, [m[e] for e in range(12)], 'numpy', cse=True)
        out('lambdify', n, time.perf_counter() - t0)
        return f
    f = limited('lambdify', n, compile, 3 * timeout) if vm else None
    def evaluate():
        x = [deltas(n, i, points) for i in range(4 * n)]
        spent, r = 0.0, 0
        while r < reps and spent < budget:
            t0 = time.perf_counter(); res = [np.asarray(a) for a in f(*x)]; t = time.perf_counter() - t0
            out('eval', n, t); spent += t; r += 1
        out('val', n, *['%.17g' % float(np.broadcast_to(a, (points,))[0]) for a in res])
    if f: limited('eval', n, evaluate)
    vm = f = None

def deep_build():
    clear_cache()
    t0 = time.perf_counter(); v, m = chain(deep); out('deepbuild', deep, time.perf_counter() - t0)
limited('deepbuild', deep, deep_build, 4 * timeout)
out('done')
)PY";

struct SympyResults {
  std::map<int, std::vector<double>> check;  // n -> 12 values + jacobian entry
  std::map<int, std::vector<double>> build, jac, eval, val, lambdify;
  std::map<std::string, std::vector<int>> timeouts;
  std::optional<double> deep_build;
};

SympyResults run_sympy(const Config& cfg,
                       const std::map<int, std::vector<double>>& expected_check) {
  char path[] = "/tmp/spar_symbolic_bench_XXXXXX.py";
  const int fd = mkstemps(path, 3);
  if (fd < 0) fail("cannot create the SymPy script file");
  if (write(fd, kSympyScript, std::strlen(kSympyScript)) < 0) fail("cannot write SymPy script");
  close(fd);
  std::string sizes;
  for (int n : kSizes) sizes += (sizes.empty() ? "" : ",") + std::to_string(n);
  // Whole-script safety net: each workload has its own timeout inside the script.
  const double total_limit = 60 * cfg.peer_timeout + 60;
  std::ostringstream cmd;
  cmd << "timeout -s KILL " << int(total_limit) << " /usr/bin/python3 " << path << " "
      << cfg.peer_budget << " " << cfg.peer_timeout << " " << cfg.repetitions << " " << cfg.points
      << " " << cfg.deep << " " << sizes << " 2>&1";
  std::fflush(stdout);
  FILE* pipe_in = popen(cmd.str().c_str(), "r");
  if (!pipe_in) fail("cannot run /usr/bin/python3");
  SympyResults r;
  char line[1 << 16];
  bool done = false;
  while (std::fgets(line, sizeof line, pipe_in)) {
    std::istringstream in(line);
    std::string key;
    in >> key;
    int n = 0;
    std::vector<double> values;
    double v;
    if (key == "timeout") {
      std::string what;
      in >> what >> n;
      r.timeouts[what].push_back(n);
      continue;
    }
    if (key == "done") {
      done = true;
      continue;
    }
    in >> n;
    while (in >> v) values.push_back(v);
    if (key == "check") {
      const std::vector<double>& ours = expected_check.at(n);
      const double diff = max_abs_diff(ours.data(), values.data(), 13);
      std::printf(
          "check n=%d sympy: m[0][3] = %.12f, d m[0][3]/d dt0 = %.12f, max |diff| vs "
          "spar over 12 entries + Jacobian entry = %.2e\n",
          n, values[3], values[12], diff);
      if (values.size() != 13 || !(diff < 1e-9)) {
        pclose(pipe_in);
        fail("SymPy disagrees with spar at n=" + std::to_string(n));
      }
      r.check[n] = values;
    } else if (key == "build") {
      r.build[n].push_back(values.at(0));
    } else if (key == "jac") {
      r.jac[n].push_back(values.at(0));
    } else if (key == "eval") {
      r.eval[n].push_back(values.at(0));
    } else if (key == "lambdify") {
      r.lambdify[n].push_back(values.at(0));
    } else if (key == "val") {
      r.val[n] = values;
    } else if (key == "deepbuild") {
      r.deep_build = values.at(0);
    } else {
      std::printf("sympy: %s", line);  // e.g. a Python traceback
    }
  }
  pclose(pipe_in);
  std::remove(path);
  if (!done)
    std::printf("sympy: the script did not finish (killed after %d s)\n", int(total_limit));
  return r;
}

// ---- spar workloads -----------------------------------------------------------------------

struct SparRow {
  int n{0};
  double build{NAN}, jacobian{NAN}, compile{NAN}, batch{NAN}, scalar{NAN};
  std::size_t dag{0}, instructions{0};
  double tree{0};
  std::vector<double> outputs;  // 12 × points, evaluate_batch layout
};

// Seconds to build a chain of n transforms in a fresh pool (freed after the clock stops).
double timed_build(int n) {
  const Clock::time_point start = Clock::now();
  sym::ExprPool pool;
  const SparChain chain = spar_chain(pool, n);
  const double seconds = seconds_since(start);
  if (chain.m[3].is_null()) std::abort();
  return seconds;
}

// Median build times of chains of n1 and n2 transforms, their builds alternated so that both
// meet the same machine: the rows' builds of one n run seconds apart from the other's, and on
// a shared VM the machine's speed changes between such stretches (their ratio ranged 1.2-3.7
// with one binary whose alternated ratio was 2.0-2.1; bench/RESULTS.md, issue 13, session 7).
std::pair<double, double> paired_build_times(int n1, int n2) {
  std::vector<double> t1, t2;
  for (int rep = 0; rep < kBuildRepetitions; ++rep) {
    t1.push_back(timed_build(n1));
    t2.push_back(timed_build(n2));
  }
  return {median(t1), median(t2)};
}

SparRow spar_workloads(int n, const Config& cfg, const std::vector<double>& x) {
  SparRow row;
  row.n = n;
  std::vector<double> times;
  // A build takes 20-400 us: the median of many, so that one page fault or preemption does not
  // move it. Each pool is fresh (no hash-consing hits from earlier repetitions) but, after the
  // first, starts from the thread's spare arrays (expr.cpp), as a planner's next instance does.
  for (int rep = 0; rep < std::max(cfg.repetitions, kBuildRepetitions); ++rep)
    times.push_back(timed_build(n));
  row.build = median(times);

  times.clear();
  for (int rep = 0; rep < cfg.repetitions; ++rep) {
    sym::ExprPool pool;
    const SparChain chain = spar_chain(pool, n);
    const std::vector<sym::Expr> position = {chain.m[3], chain.m[7], chain.m[11]};
    const Clock::time_point start = Clock::now();
    const auto jac = sym::jacobian(position, chain.variables);
    times.push_back(seconds_since(start));
    if (jac.size() != 3 || jac[0].size() != chain.variables.size()) std::abort();
  }
  row.jacobian = median(times);

  sym::ExprPool pool;
  const SparChain chain = spar_chain(pool, n);
  std::vector<sym::Expr> entries;
  for (int e : kEntries) entries.push_back(chain.m[e]);
  row.dag = sym::dag_size(entries);
  for (sym::Expr e : entries) row.tree += sym::tree_size(e);

  times.clear();
  std::optional<sym::Tape> tape;
  for (int rep = 0; rep < cfg.repetitions; ++rep) {
    const Clock::time_point start = Clock::now();
    tape.emplace(sym::Tape::compile(entries, chain.variables));
    times.push_back(seconds_since(start));
  }
  row.compile = median(times);
  row.instructions = tape->instructions().size();

  const std::size_t points = x.size() / chain.variables.size();
  row.outputs.assign(12 * points, 0.0);
  times.clear();
  for (int rep = 0; rep < cfg.repetitions; ++rep) {
    const Clock::time_point start = Clock::now();
    sym::evaluate_batch(*tape, x, row.outputs, points);
    times.push_back(seconds_since(start));
  }
  row.batch = median(times);

  // TapeEvaluator<double>, one point at a time (inputs gathered per point beforehand, untimed).
  std::vector<double> per_point(x.size());
  const std::size_t inputs = chain.variables.size();
  for (std::size_t i = 0; i < inputs; ++i)
    for (std::size_t p = 0; p < points; ++p) per_point[p * inputs + i] = x[i * points + p];
  sym::TapeEvaluator<double> evaluator(*tape);
  std::array<double, 12> out{};
  double sink = 0;
  times.clear();
  for (int rep = 0; rep < std::max(1, cfg.repetitions / 2); ++rep) {
    const Clock::time_point start = Clock::now();
    for (std::size_t p = 0; p < points; ++p) {
      evaluator.evaluate(std::span<const double>(&per_point[p * inputs], inputs), out);
      sink += out[3];
    }
    times.push_back(seconds_since(start));
  }
  row.scalar = median(times);
  if (std::isnan(sink)) std::abort();
  return row;
}

std::string peer_cell(const PeerTime& t) {
  if (t.kind == PeerTime::Kind::kNotRun) return t.note.empty() ? "-" : t.note;
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s%.4g s (%s)", t.kind == PeerTime::Kind::kLowerBound ? ">" : "",
                t.seconds, t.note.c_str());
  return buf;
}

void print_ratio(const std::string& workload, const char* peer, const PeerTime& t, double ours) {
  if (t.kind == PeerTime::Kind::kNotRun) return;
  const char* note = t.kind == PeerTime::Kind::kLowerBound  ? "   # lower bound"
                     : t.kind == PeerTime::Kind::kEstimated ? "   # peer time estimated"
                                                            : "";
  std::printf("ratio %s %s %.1f%s\n", workload.c_str(), peer, t.seconds / ours, note);
}

PeerTime add(const PeerTime& a, const PeerTime& b) {
  PeerTime t;
  t.kind = std::max(a.kind, b.kind);
  t.seconds = a.seconds + b.seconds;
  t.note = a.note + " + " + b.note;
  return t;
}

// 1. Agreement before timing: spar (tape), GiNaC (subs+evalf), independent double product. The
// values checked, by n (12 entries and one Jacobian entry), for SymPy to check against.
std::map<int, std::vector<double>> check_agreement(const Config& cfg) {
  std::map<int, std::vector<double>> check;
  for (int n : {6, 12}) {
    sym::ExprPool pool;
    const SparChain chain = spar_chain(pool, n);
    std::vector<sym::Expr> entries(chain.m.begin(), chain.m.begin() + 12);
    const sym::Tape tape = sym::Tape::compile(entries, chain.variables);
    std::vector<double> point(chain.variables.size());
    std::map<std::string, double> named;
    for (std::size_t i = 0; i < point.size(); ++i) {
      point[i] = delta(n, i, 0, cfg.points);
      named[chain.variables[i].name()] = point[i];
    }
    std::vector<double> ours(13);
    sym::TapeEvaluator<double>(tape).evaluate(point, std::span<double>(ours.data(), 12));
    ours[12] = sym::evaluate(sym::differentiate(chain.m[3], chain.variables[3]), named);
    const std::vector<double> ginac = run_in_child(60, [&](auto emit) {
      const GinacChain g = ginac_chain(n);
      GiNaC::exmap values;
      for (std::size_t i = 0; i < point.size(); ++i) values[g.variables[i]] = point[i];
      for (int e : kEntries)
        emit(GiNaC::ex_to<GiNaC::numeric>(g.m[e].subs(values).evalf()).to_double());
      emit(GiNaC::ex_to<GiNaC::numeric>(g.m[3].diff(g.variables[3]).subs(values).evalf())
               .to_double());
    });
    const std::array<double, 12> ref = reference_values(n, 0, cfg.points);
    if (ginac.size() != 13) fail("GiNaC check did not finish");
    const double d_ginac = max_abs_diff(ours.data(), ginac.data(), 13);
    const double d_ref = max_abs_diff(ours.data(), ref.data(), 12);
    std::printf("check n=%d spar:  m[0][3] = %.12f, d m[0][3]/d dt0 = %.12f\n", n, ours[3],
                ours[12]);
    std::printf(
        "check n=%d ginac: m[0][3] = %.12f, d m[0][3]/d dt0 = %.12f, max |diff| = %.2e; "
        "plain double product: max |diff| = %.2e\n",
        n, ginac[3], ginac[12], d_ginac, d_ref);
    if (!(d_ginac < 1e-9) || !(d_ref < 1e-9)) fail("GiNaC or the double product disagrees");
    check[n] = ours;
  }
  return check;
}

// A workload's times: spar's and the peers'.
struct Ratios {
  std::string workload;
  PeerTime ginac, sympy;
  double ours;
};

// 3. spar and GiNaC (and SymPy's times from `sympy`) on the chain of n transforms: its rows,
// its ratios, and spar's build time.
void size_rows(int n, const Config& cfg, const SympyResults& sympy, std::vector<Ratios>& ratios,
               std::map<int, double>& build_time) {
  const std::vector<double> x = make_points(n, cfg.points);
  const SparRow row = spar_workloads(n, cfg, x);
  build_time[n] = row.build;
  const std::size_t vars = 4 * static_cast<std::size_t>(n);

  // Values: every point the peers computed, and the double reference at point 0.
  const std::array<double, 12> ref = reference_values(n, 0, cfg.points);
  double d_ref = 0;
  for (int e = 0; e < 12; ++e)
    d_ref = std::max(d_ref, std::fabs(ref[e] - row.outputs[e * cfg.points]));
  if (!(d_ref < 1e-9)) fail("tape disagrees with the double product at n=" + std::to_string(n));

  const PeerTime g_build =
      summarize(run_in_child(cfg.peer_timeout, [&](auto emit) { ginac_build(n, cfg, emit); }), 1,
                cfg.peer_timeout, "repetitions");
  const PeerTime g_jac = summarize(
      run_in_child(3 * cfg.peer_timeout, [&](auto emit) { ginac_jacobian(n, cfg, emit); }), vars,
      cfg.peer_timeout, "columns");
  const std::vector<double> g_eval_raw =
      run_in_child(3 * cfg.peer_timeout, [&](auto emit) { ginac_eval(n, cfg, x, emit); });
  std::vector<double> g_point_times;
  double d_ginac = 0;
  for (std::size_t p = 0; (p + 1) * 13 <= g_eval_raw.size(); ++p) {
    g_point_times.push_back(g_eval_raw[p * 13]);
    for (int e = 0; e < 12; ++e)
      d_ginac = std::max(d_ginac,
                         std::fabs(g_eval_raw[p * 13 + 1 + e] - row.outputs[e * cfg.points + p]));
  }
  if (!(d_ginac < 1e-9)) fail("GiNaC evaluation disagrees at n=" + std::to_string(n));
  const PeerTime g_eval = summarize(g_point_times, cfg.points, cfg.peer_timeout, "points");

  auto sympy_time = [&](const std::map<int, std::vector<double>>& m, std::size_t per_rep,
                        const char* what, const char* unit) {
    const auto it = m.find(n);
    std::vector<double> units = it == m.end() ? std::vector<double>{} : it->second;
    const auto timed_out = sympy.timeouts.find(what);
    const bool hit = timed_out != sympy.timeouts.end() &&
                     std::count(timed_out->second.begin(), timed_out->second.end(), n) > 0;
    if (!units.empty() || hit) return summarize(units, per_rep, cfg.peer_timeout, unit);
    for (const char* before : {"setup_jac", "setup_eval", "lambdify"}) {
      const auto it2 = sympy.timeouts.find(before);
      if (it2 != sympy.timeouts.end() && std::count(it2->second.begin(), it2->second.end(), n))
        return PeerTime{PeerTime::Kind::kNotRun, NAN,
                        std::string("not run: ") + before + " > " +
                            std::to_string(int(3 * cfg.peer_timeout)) + " s"};
    }
    return PeerTime{};
  };
  const PeerTime s_build = sympy_time(sympy.build, 1, "build", "repetitions");
  const PeerTime s_jac = sympy_time(sympy.jac, vars, "jac", "columns");
  const PeerTime s_eval = sympy_time(sympy.eval, 1, "eval", "repetitions");
  double d_sympy = NAN;
  if (const auto it = sympy.val.find(n); it != sympy.val.end() && it->second.size() == 12) {
    d_sympy = 0;
    for (int e = 0; e < 12; ++e)
      d_sympy = std::max(d_sympy, std::fabs(it->second[e] - row.outputs[e * cfg.points]));
    if (!(d_sympy < 1e-9)) fail("SymPy evaluation disagrees at n=" + std::to_string(n));
  }
  PeerTime s_compile;
  if (const auto it = sympy.lambdify.find(n); it != sympy.lambdify.end()) {
    s_compile = {PeerTime::Kind::kMeasured, it->second.at(0), "1 run"};
  } else if (sympy.timeouts.count("lambdify") &&
             std::count(sympy.timeouts.at("lambdify").begin(), sympy.timeouts.at("lambdify").end(),
                        n)) {
    s_compile = {PeerTime::Kind::kLowerBound, 3 * cfg.peer_timeout, "timed out"};
  }
  const std::string lambdify = peer_cell(s_compile);

  const double ns_per_instruction =
      row.batch / (static_cast<double>(cfg.points) * row.instructions) * 1e9;
  std::printf(
      "%-4d DAG %zu nodes, tree %.4g nodes (12 entries); tape %zu instructions, "
      "compile %.3g ms; evaluated values agree: double product %.1e, GiNaC %.1e (%zu "
      "points), SymPy %.1e (point 0); SymPy lambdify(cse=True) %s\n",
      n, row.dag, row.tree, row.instructions, row.compile * 1e3, d_ref, d_ginac,
      g_point_times.size(), d_sympy, lambdify.c_str());
  auto line = [&](const char* workload, double ours, const char* extra, const PeerTime& g,
                  const PeerTime& s) {
    std::printf("%-4d %-10s %10.4g s %-36s | %-34s | %-34s\n", n, workload, ours, extra,
                peer_cell(g).c_str(), peer_cell(s).c_str());
  };
  line("build", row.build, "", g_build, s_build);
  line("jacobian", row.jacobian, "", g_jac, s_jac);
  char extra[64];
  std::snprintf(extra, sizeof extra, "(batch; %.2f ns/instr)", ns_per_instruction);
  line("eval", row.batch, extra, g_eval, s_eval);
  std::snprintf(extra, sizeof extra, "(TapeEvaluator, %.2f ns/instr)",
                row.scalar / (static_cast<double>(cfg.points) * row.instructions) * 1e9);
  line("eval1", row.scalar, extra, PeerTime{}, PeerTime{});
  const std::string suffix = "_n" + std::to_string(n);
  ratios.push_back({"build" + suffix, g_build, s_build, row.build});
  ratios.push_back({"jacobian" + suffix, g_jac, s_jac, row.jacobian});
  ratios.push_back({"build+jacobian" + suffix, add(g_build, g_jac), add(s_build, s_jac),
                    row.build + row.jacobian});
  ratios.push_back({"eval" + suffix, g_eval, s_eval, row.batch});
  ratios.push_back({"compile" + suffix, PeerTime{}, s_compile, row.compile});
}

// 4. The deep chain (spar's build against the peers', and issue 13's per-transform targets).
void deep_chain(const Config& cfg, const SympyResults& sympy,
                const std::map<int, double>& build_time, std::vector<Ratios>& ratios) {
  const int n = cfg.deep;
  const int deep_reps = cfg.quick ? 1 : 3;
  std::vector<double> times;
  for (int rep = 1; rep < deep_reps; ++rep) times.push_back(timed_build(n));
  const Clock::time_point build_start = Clock::now();
  sym::ExprPool pool;  // the last repetition's chain is the one evaluated below
  const SparChain chain = spar_chain(pool, n);
  times.push_back(seconds_since(build_start));
  const double build = median(times);
  std::vector<sym::Expr> entries(chain.m.begin(), chain.m.begin() + 12);
  const std::size_t dag = sym::dag_size(entries);
  const double tree = sym::tree_size(chain.m[3]);
  Clock::time_point start = Clock::now();
  const sym::Tape tape = sym::Tape::compile(entries, chain.variables);
  const double compile = seconds_since(start);
  const std::vector<double> x = make_points(n, cfg.deep_points);
  std::vector<double> out(12 * cfg.deep_points);
  start = Clock::now();
  sym::evaluate_batch(tape, x, out, cfg.deep_points);
  const double batch = seconds_since(start);
  const std::array<double, 12> ref = reference_values(n, 0, cfg.deep_points);
  double d_ref = 0;
  for (int e = 0; e < 12; ++e)
    d_ref = std::max(d_ref, std::fabs(ref[e] - out[e * cfg.deep_points]));
  if (!(d_ref < 1e-9)) fail("deep chain: tape disagrees with the double product");
  Config one = cfg;
  one.repetitions = deep_reps;
  one.peer_timeout = cfg.quick ? 3 : 60;
  const PeerTime g_build =
      summarize(run_in_child(one.peer_timeout, [&](auto emit) { ginac_build(n, one, emit); }), 1,
                one.peer_timeout, "repetitions");
  PeerTime s_build;
  if (sympy.deep_build) {
    s_build = {PeerTime::Kind::kMeasured, *sympy.deep_build, "1 run"};
  } else if (sympy.timeouts.count("deepbuild")) {
    s_build = {PeerTime::Kind::kLowerBound, 4 * cfg.peer_timeout, "timed out"};
  }
  std::printf("\ndeep chain n=%d: build %.4g s (median of %d) | GiNaC %s | SymPy %s\n", n, build,
              deep_reps, peer_cell(g_build).c_str(), peer_cell(s_build).c_str());
  std::printf(
      "deep chain: DAG %zu nodes for 12 entries, tree of m[0][3] %.4g nodes (inf: beyond "
      "1.8e308); tape %zu instructions, %zu slots, compile %.4g s; evaluate_batch %zu points "
      "%.4g s = %.2f "
      "ns/instr; agrees with the double product to %.1e. The peers' trees cannot be "
      "evaluated (exponential), not attempted.\n",
      dag, tree, tape.instructions().size(), tape.slot_count(), compile, cfg.deep_points, batch,
      batch / (static_cast<double>(cfg.deep_points) * tape.instructions().size()) * 1e9, d_ref);
  ratios.push_back({"deep_build", g_build, s_build, build});
  // Issue 13's targets: cost per transform independent of the pool's size.
  std::printf("build per transform:");
  for (const auto& [size, time] : build_time)
    std::printf(" n=%d %.2f us,", size, time / size * 1e6);
  std::printf(" deep %.2f us (target <= 10 us: %s)\n", build / n * 1e6,
              build / n <= 10e-6 ? "met" : "MISSED");
  const auto [t24, t48] = paired_build_times(24, 48);
  const double growth = t48 / t24;
  std::printf(
      "build n=48 / n=24: %.2f from the rows above; %.2f from %d builds of each, alternated "
      "(%.4g / %.4g s; target <= 2.2: %s)\n",
      build_time.at(48) / build_time.at(24), growth, kBuildRepetitions, t48, t24,
      growth <= 2.2 ? "met" : "MISSED");
}

}  // namespace

int main(int argc, char** argv) {
  Config cfg;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      cfg.quick = true;
      cfg.repetitions = 3;
      cfg.peer_budget = 0.4;
      cfg.peer_timeout = 0.8;
      cfg.deep_points = 50;
    } else {
      std::fprintf(stderr, "usage: %s [--quick]\n", argv[0]);
      return 2;
    }
  }
  std::printf(
      "symbolic_bench%s: chain of n uncertain transforms; %zu evaluation points; peer "
      "budget %.1f s per workload (hard limit %.1f s)\n",
      cfg.quick ? " --quick" : "", cfg.points, cfg.peer_budget, cfg.peer_timeout);

  const std::map<int, std::vector<double>> check = check_agreement(cfg);

  // 2. SymPy (its own process; it re-checks the values above before timing anything).
  const SympyResults sympy = run_sympy(cfg, check);

  std::printf("\n%-4s %-10s %-10s %-12s %-10s %-8s %-7s | %-34s | %-34s\n", "n", "workload", "spar",
              "", "", "", "", "GiNaC 1.8.6", "SymPy");
  std::vector<Ratios> ratios;
  std::map<int, double> build_time;  // spar's, by n
  for (int n : kSizes) size_rows(n, cfg, sympy, ratios, build_time);
  deep_chain(cfg, sympy, build_time, ratios);

  std::printf("\n");
  for (const Ratios& r : ratios) {
    print_ratio(r.workload, "ginac", r.ginac, r.ours);
    print_ratio(r.workload, "sympy", r.sympy, r.ours);
  }
  return 0;
}

// SMP: the on-request simplifier.
//
// Construction already keeps expressions canonical (expr.hpp). SMP goes further when asked, with
// one goal: make interval evaluation tight. Every repeated occurrence of a variable loosens an
// interval bound (x - x over [0, 1] evaluates to [-1, 1]), so SMP minimises the occurrence cost
//     cost(f) = Σ_v width(v) · max(0, occurrences_v(f) - 1)        (width 1 when no box is known)
// counted on f as a tree (a shared subexpression counts once per use; a domain guard 0·t, see
// expr.hpp, counts nothing: it encloses to [0, 0]), then the tree size. No rewrite loses a domain:
// every rewrite is built by construction, which keeps guards for what cancels.
//
// Rewrites `simplify` applies (each one an identity wherever the original is defined):
//   parity         sin(-u) -> -sin u, tan(-u) -> -tan u, atan(-u) -> -atan u, asin(-u) -> -asin u,
//                  cos(-u) -> cos u, abs(-u) -> abs u          (always; occurrence-neutral, enables
//                                                                the rules below)
//   Pythagorean    a·R·sin²u + b·R·cos²u -> a·R + (b - a)·R·cos²u   (a = b gives a·R; R any
//   product) angle sums     a·R·cos x·cos y - a·R·sin x·sin y -> a·R·cos(x + y)   (+ gives cos(x -
//   y))
//                  a·R·sin x·cos y + a·R·cos x·sin y -> a·R·sin(x + y)   (- gives sin(x - y))
//   harmonic       a·R·cos t + b·R·sin t -> r·R·cos(t - φ), r = sqrt(a² + b²), φ = atan2(b, a),
//                  for constant a, b
//   square         a·u² + b·u -> a·(u + b/(2a))² - b²/(4a)   for constant a, b
//   factoring      Σ terms sharing a factor B^m -> B^m · Σ (term / B^m)   (x·y + x·z -> x·(y + z),
//                  x/w + y/w -> (x + y)/w)
//   quotient       c·N/D -> c·(a + r/D) when N = a·D + r for constant a, r: t/(t + 1) ->
//                  1 - 1/(t + 1)  (N: the product of the other factors, as a sum)
//   distribution   c·(s1 + s2)·P -> c·s1·P + c·s2·P when it cancels: w·(a/w + b) -> a + b·w;
//                  w·(a/w)² -> a²/w is done by construction, which merges equal bases
// A rewrite other than parity is kept only if it strictly lowers (cost, size) of the node it
// rewrites, and a final check returns the input if the whole result's occurrence cost is higher.
// Passes run bottom-up over the DAG (iteratively: any depth) until nothing changes or the budget
// runs out (work units: nodes visited while pricing candidates, plus the pairwise term matching),
// and there are at most 16 passes and 16 rewrites per node per pass: simplify always terminates.
//
// On request only, not applied by `simplify`:
//   expand         distributes products and positive integer powers of sums, everywhere
//   collect        expand, then group every sum's terms by their monomial in given variables
//
// Example:
//   ExprPool pool;
//   Expr x = pool.variable("x"), t = pool.variable("t");
//   Expr f = pow(sin(x), 2) + pow(cos(x), 2);
//   assert(simplify(f) == pool.integer(1));
//   Expr g = simplify(3 * cos(t) + 4 * sin(t));       // 5*cos(t - atan2(4, 3))
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>

#include "spar/symbolic/expr.hpp"

namespace spar::symbolic {

struct SimplifyOptions {
  // Upper bound on the work spent pricing candidate rewrites, in nodes visited. When it runs out
  // SMP stops rewriting and returns what it has (still equal in value to the input).
  std::size_t budget{2'000'000};
  // Box widths by variable name; a variable not listed has width 1. Width 0 makes repeats free.
  std::map<std::string, double> widths{};
};

// Σ_v width(v) · max(0, occurrences_v(f) - 1) over the tree form of f (see above). Linear in the
// DAG size; occurrence counts are doubles because trees grow exponentially with sharing.
[[nodiscard]] double occurrence_cost(Expr f, const std::map<std::string, double>& widths = {});

// Products and positive integer powers of sums multiplied out, everywhere (inside function
// arguments too). A product whose expansion would exceed 4096 terms is left as a product.
[[nodiscard]] Expr expand(Expr f);

// expand(f), then in every sum, terms with the same monomial in `variables` (a product of
// powers of them) are grouped: x·y + 2·x + x^2·z, collected in x -> x·(2 + y) + x^2·z.
// Every entry of `variables` must be a Variable.
[[nodiscard]] Expr collect(Expr f, std::span<const Expr> variables);

// The rewrites listed above, within the budget. occurrence_cost(simplify(f)) never exceeds
// occurrence_cost(f), and simplify(f) equals f wherever f is defined.
[[nodiscard]] Expr simplify(Expr f, const SimplifyOptions& options = {});

}  // namespace spar::symbolic

// The one table of spar's functions (sin ... max). Everything that lists them is generated from
// it, so a new function or a changed rule cannot be missed in one place:
//   symbolic::Op and symbolic::TapeOp (their function entries, in this order), function_name(),
//   the free functions sin(Expr) ..., the tape compiler's Op -> TapeOp map and
//   dispatch_instruction(), TapeDomain<double> and bounds' TapeDomain<Interval>, the parser's
//   function names (through function_name()), the symbolic derivative (operations.cpp) and the
//   partial derivatives of the gradient evaluators (bounds/internal/gradient.hpp).
//
// SPAR_UNARY_FUNCTIONS(X) calls X(Name, name, libm, derivative) per function of one argument:
//   Name        the enumerator suffix: Op::kName, TapeOp::kName
//   name        the infix syntax and the C++ function: sin(x), bounds::sin(Interval), D::sin
//   libm        the <cmath> function for doubles (fabs for abs)
//   derivative  d name(a) / da, written over a function set F that each user supplies (symbolic
//               expressions, doubles, intervals): F::sin, F::cos, F::tan, F::exp, F::sqrt,
//               F::square, F::one(), F::sign(a) (the sign of a; for intervals the
//               Clarke enclosure [-1, 1] across 0)
// SPAR_BINARY_FUNCTIONS(X) calls X(Name, name, libm, da, db) with the partial derivatives by the
//   first argument a and the second b; F::min_partial(a, b) is d min(a, b) / da (1 where a is
//   the smaller). atan2(y, x) takes y as a; its branch cut is the gradient evaluator's concern.
// The functions that restrict their domain (log, sqrt, tan, asin, acos, atan2) are listed where
// domains are decided (expr.cpp partial_node, smp.cpp DomainConditions): a domain is a property
// of the function, not of how it is computed.
//
// Example (a user: the name of every unary function):
//   #define SPAR_NAME(Name, name, libm, derivative) case Op::k##Name: return #name;
//   switch (op) { SPAR_UNARY_FUNCTIONS(SPAR_NAME) default: return ""; }
//   #undef SPAR_NAME
#pragma once

// clang-format off
#define SPAR_UNARY_FUNCTIONS(X)                                                   \
  X(Sin,  sin,  sin,  F::cos(a))                                                  \
  X(Cos,  cos,  cos,  -F::sin(a))                                                 \
  X(Tan,  tan,  tan,  F::one() + F::square(F::tan(a)))                            \
  X(Sqrt, sqrt, sqrt, F::one() / (2 * F::sqrt(a)))                                \
  X(Exp,  exp,  exp,  F::exp(a))                                                  \
  X(Log,  log,  log,  F::one() / a)                                               \
  X(Abs,  abs,  fabs, F::sign(a))                                                 \
  X(Atan, atan, atan, F::one() / (F::one() + F::square(a)))                       \
  X(Asin, asin, asin, F::one() / F::sqrt(F::one() - F::square(a)))                \
  X(Acos, acos, acos, -(F::one() / F::sqrt(F::one() - F::square(a))))

#define SPAR_BINARY_FUNCTIONS(X)                                                  \
  X(Atan2, atan2, atan2, b / (F::square(a) + F::square(b)),                       \
                         -(a / (F::square(a) + F::square(b))))                    \
  X(Min,   min,   fmin,  F::min_partial(a, b), F::min_partial(b, a))              \
  X(Max,   max,   fmax,  F::min_partial(b, a), F::min_partial(a, b))
// clang-format on

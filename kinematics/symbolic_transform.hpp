// SymbolicTransform: 4x4 homogeneous rigid transforms whose entries are symbolic expressions.
//
// A transform is stored structured, as (R, t): a 3x3 rotation and a translation, the bottom row
// [0 0 0 1] implicit. Composition is (R1, t1)(R2, t2) = (R1 R2, R1 t2 + t1) and the inverse is the
// RIGID inverse (R^T, -R^T t), never a general matrix inverse. Every entry is built as one
// canonical sum c0 + sum ci*ti: a product with a constant 0 entry is skipped, a product with a
// constant entry becomes a coefficient (so a constant 1 costs nothing), and constants fold, so
// numeric poses composed with each other stay numbers and identity factors add no node.
//
// The rotation is orthonormal for every value of the variables as long as the transform is built
// from trans/rotx/roty/rotz, numeric rigid poses (from_numeric), products and rigid inverses.
//
// Example:
//   ExprPool pool;
//   const Expr theta = pool.variable("theta"), x = pool.variable("x");
//   const SymbolicTransform frame = trans(x, pool.integer(0), pool.integer(2)) * rotz(theta);
//   const SymbolicPoint origin = rigid_inverse(frame).apply(frame.translation());  // ~ (0, 0, 0)
//   const Transform pose = frame.evaluate({{"theta", 0.3}, {"x", 1.0}});           // numeric
#pragma once

#include <array>
#include <map>
#include <string>

#include "spar/kinematics/dh.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::kinematics {

// A point (or vector) with symbolic coordinates x, y, z.
using SymbolicPoint = std::array<symbolic::Expr, 3>;

class SymbolicTransform {
 public:
  // The identity.
  explicit SymbolicTransform(symbolic::ExprPool& pool);
  // `rotation` row-major. All entries must belong to `pool`; the caller guarantees orthonormality.
  SymbolicTransform(symbolic::ExprPool& pool, const std::array<symbolic::Expr, 9>& rotation,
                    const SymbolicPoint& translation);
  // A numeric rigid pose as exact constants.
  [[nodiscard]] static SymbolicTransform from_numeric(symbolic::ExprPool& pool,
                                                      const Transform& pose);

  [[nodiscard]] symbolic::ExprPool& pool() const { return *pool_; }
  [[nodiscard]] symbolic::Expr rotation(int row, int column) const {
    return rotation_[row * 3 + column];
  }
  [[nodiscard]] const SymbolicPoint& translation() const { return translation_; }
  // Entry (row, column) of the 4x4 matrix, bottom row included.
  [[nodiscard]] symbolic::Expr entry(int row, int column) const;

  // R p + t: the point p given in this frame, expressed in the parent frame.
  [[nodiscard]] SymbolicPoint apply(const SymbolicPoint& point) const;
  // R^T (p - t): the parent-frame point p expressed in this frame (rigid inverse, applied).
  [[nodiscard]] SymbolicPoint apply_inverse(const SymbolicPoint& point) const;
  // Coordinate `row` (0, 1, 2) of apply_inverse(point) alone: (R^T)_row · (p - t).
  [[nodiscard]] symbolic::Expr apply_inverse_coordinate(const SymbolicPoint& point, int row) const;
  // The numeric pose at a point (every variable of every entry needs a value; throws
  // symbolic::SymbolicError otherwise).
  [[nodiscard]] Transform evaluate(const std::map<std::string, double>& values) const;

  friend SymbolicTransform operator*(const SymbolicTransform& a, const SymbolicTransform& b);

 private:
  symbolic::ExprPool* pool_;                // owns every entry; outlives this transform
  std::array<symbolic::Expr, 9> rotation_;  // row-major 3x3 rotation, orthonormal (see above)
  SymbolicPoint translation_;
};

// (R^T, -R^T t).
[[nodiscard]] SymbolicTransform rigid_inverse(const SymbolicTransform& transform);

// Elementary transforms; arguments of one call must share a pool.
[[nodiscard]] SymbolicTransform trans(symbolic::Expr x, symbolic::Expr y, symbolic::Expr z);
[[nodiscard]] SymbolicTransform trans(symbolic::ExprPool& pool, double x, double y, double z);
[[nodiscard]] SymbolicTransform rotx(symbolic::Expr theta);
[[nodiscard]] SymbolicTransform roty(symbolic::Expr theta);
[[nodiscard]] SymbolicTransform rotz(symbolic::Expr theta);

// A point with constant coordinates.
[[nodiscard]] SymbolicPoint constant_point(symbolic::ExprPool& pool, double x, double y, double z);
[[nodiscard]] SymbolicPoint constant_point(symbolic::ExprPool& pool, const Eigen::Vector3d& p);

}  // namespace spar::kinematics

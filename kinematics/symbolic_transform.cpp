#include "spar/kinematics/symbolic_transform.hpp"

#include <array>
#include <span>
#include <utility>
#include <vector>

#include "spar/symbolic/operations.hpp"

namespace spar::kinematics {

using symbolic::Expr;
using symbolic::ExprPool;
using symbolic::Number;
using symbolic::Term;

namespace {

bool is_constant_zero(Expr e) { return e.is_constant() && e.constant().is_zero(); }

// addend + sum of a_k * b_k as one canonical sum. A product with a constant 0 factor is skipped, a
// constant factor becomes the term's coefficient (no product node is built), and a product of two
// constants folds into the constant term.
Expr sum_of_products(ExprPool& pool, const std::array<std::pair<Expr, Expr>, 3>& products,
                     Expr addend) {
  Number constant;
  std::array<Term, 4> terms;  // on the stack: every transform entry builds one
  std::size_t count = 0;
  const auto add_term = [&](Expr e, const Number& coefficient) {
    if (e.is_constant()) {
      constant = constant + e.constant() * coefficient;
    } else {
      terms[count++] = {e, coefficient};
    }
  };
  for (const auto& [a, b] : products) {
    if (is_constant_zero(a) || is_constant_zero(b)) continue;
    if (a.is_constant()) {
      add_term(b, a.constant());
    } else if (b.is_constant()) {
      add_term(a, b.constant());
    } else {
      terms[count++] = {a * b, Number::integer(1)};
    }
  }
  if (!addend.is_null()) add_term(addend, Number::integer(1));
  if (count == 0) return pool.constant(constant);
  return pool.sum(constant, std::span<const Term>(terms.data(), count));
}

// Row-major rotation about one axis: the two coordinates other than `axis` rotate by theta.
SymbolicTransform axis_rotation(Expr theta, int axis) {
  ExprPool& pool = theta.pool();
  const Expr zero = pool.integer(0), one = pool.integer(1);
  const Expr c = cos(theta), s = sin(theta);
  std::array<Expr, 9> r;
  r.fill(zero);
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // right-handed: (y, z), (z, x), (x, y)
  r[axis * 3 + axis] = one;
  r[i * 3 + i] = c;
  r[i * 3 + j] = -s;
  r[j * 3 + i] = s;
  r[j * 3 + j] = c;
  return SymbolicTransform(pool, r, {zero, zero, zero});
}

}  // namespace

SymbolicTransform::SymbolicTransform(ExprPool& pool) : pool_(&pool) {
  const Expr zero = pool.integer(0), one = pool.integer(1);
  rotation_ = {one, zero, zero, zero, one, zero, zero, zero, one};
  translation_ = {zero, zero, zero};
}

SymbolicTransform::SymbolicTransform(ExprPool& pool, const std::array<Expr, 9>& rotation,
                                     const SymbolicPoint& translation)
    : pool_(&pool), rotation_(rotation), translation_(translation) {
  for (const Expr e : rotation_) {
    if (&e.pool() != pool_) throw KinematicsError("SymbolicTransform: entry from another pool");
  }
  for (const Expr e : translation_) {
    if (&e.pool() != pool_) throw KinematicsError("SymbolicTransform: entry from another pool");
  }
}

SymbolicTransform SymbolicTransform::from_numeric(ExprPool& pool, const Transform& pose) {
  std::array<Expr, 9> rotation;
  SymbolicPoint translation;
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      rotation[row * 3 + column] = pool.constant(pose.linear()(row, column));
    }
    translation[row] = pool.constant(pose.translation()(row));
  }
  return SymbolicTransform(pool, rotation, translation);
}

Expr SymbolicTransform::entry(int row, int column) const {
  if (row == 3) return pool_->integer(column == 3 ? 1 : 0);
  return column == 3 ? translation_[row] : rotation(row, column);
}

SymbolicPoint SymbolicTransform::apply(const SymbolicPoint& point) const {
  SymbolicPoint result;
  for (int row = 0; row < 3; ++row) {
    const std::array<std::pair<Expr, Expr>, 3> products = {
        {{rotation(row, 0), point[0]}, {rotation(row, 1), point[1]}, {rotation(row, 2), point[2]}}};
    result[row] = sum_of_products(*pool_, products, translation_[row]);
  }
  return result;
}

SymbolicPoint SymbolicTransform::apply_inverse(const SymbolicPoint& point) const {
  return {apply_inverse_coordinate(point, 0), apply_inverse_coordinate(point, 1),
          apply_inverse_coordinate(point, 2)};
}

Expr SymbolicTransform::apply_inverse_coordinate(const SymbolicPoint& point, int row) const {
  // Entries of p - t are built only where column `row` of R is not a constant 0.
  std::array<std::pair<Expr, Expr>, 3> products;
  for (int k = 0; k < 3; ++k) {
    const Expr r = rotation(k, row);
    products[k] = {r, is_constant_zero(r) ? r : point[k] - translation_[k]};
  }
  return sum_of_products(*pool_, products, Expr());
}

Transform SymbolicTransform::evaluate(const std::map<std::string, double>& values) const {
  Transform pose = Transform::Identity();
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      pose.linear()(row, column) = symbolic::evaluate(rotation(row, column), values);
    }
    pose.translation()(row) = symbolic::evaluate(translation_[row], values);
  }
  return pose;
}

SymbolicTransform operator*(const SymbolicTransform& a, const SymbolicTransform& b) {
  if (a.pool_ != b.pool_) throw KinematicsError("SymbolicTransform: operands from two pools");
  std::array<Expr, 9> rotation;
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      const std::array<std::pair<Expr, Expr>, 3> products = {
          {{a.rotation(row, 0), b.rotation(0, column)},
           {a.rotation(row, 1), b.rotation(1, column)},
           {a.rotation(row, 2), b.rotation(2, column)}}};
      rotation[row * 3 + column] = sum_of_products(*a.pool_, products, Expr());
    }
  }
  return SymbolicTransform(*a.pool_, rotation, a.apply(b.translation_));
}

SymbolicTransform rigid_inverse(const SymbolicTransform& transform) {
  std::array<Expr, 9> rotation;
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) {
      rotation[row * 3 + column] = transform.rotation(column, row);
    }
  }
  ExprPool& pool = transform.pool();
  const Expr zero = pool.integer(0);
  return SymbolicTransform(pool, rotation, transform.apply_inverse({zero, zero, zero}));
}

SymbolicTransform trans(Expr x, Expr y, Expr z) {
  ExprPool& pool = x.pool();
  const Expr zero = pool.integer(0), one = pool.integer(1);
  return SymbolicTransform(pool, {one, zero, zero, zero, one, zero, zero, zero, one}, {x, y, z});
}

SymbolicTransform trans(ExprPool& pool, double x, double y, double z) {
  return trans(pool.constant(x), pool.constant(y), pool.constant(z));
}

SymbolicTransform rotx(Expr theta) { return axis_rotation(theta, 0); }
SymbolicTransform roty(Expr theta) { return axis_rotation(theta, 1); }
SymbolicTransform rotz(Expr theta) { return axis_rotation(theta, 2); }

SymbolicPoint constant_point(ExprPool& pool, double x, double y, double z) {
  return {pool.constant(x), pool.constant(y), pool.constant(z)};
}
SymbolicPoint constant_point(ExprPool& pool, const Eigen::Vector3d& p) {
  return constant_point(pool, p.x(), p.y(), p.z());
}

}  // namespace spar::kinematics

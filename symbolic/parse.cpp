#include "spar/symbolic/parse.hpp"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "spar/symbolic/operations.hpp"

namespace spar::symbolic {
namespace {

// The message for a non-ASCII character (a UTF-8 sequence starting at byte `at`): the character,
// its column and what to write instead.
std::string non_ascii_message(std::string_view text, std::size_t at) {
  std::size_t end = at + 1;
  while (end < text.size() && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) ++end;
  return "non-ASCII character '" + std::string(text.substr(at, end - at)) + "' at column " +
         std::to_string(at + 1) + " in '" + std::string(text) + "': " + kAsciiHint;
}

// 12 bytes: the text is a view into the input (a million-term input is 7 million tokens).
struct Token {
  enum Kind : std::uint8_t { kNumber, kName, kSymbol, kEnd } kind;
  char symbol;           // kSymbol: + - * / ^ ( ) ,  ('**' is '^')
  std::uint32_t start;   // byte offset in the input
  std::uint32_t length;  // bytes
  [[nodiscard]] std::size_t column() const { return std::size_t{start} + 1; }
};

class Parser {
 public:
  Parser(ExprPool& pool, std::string_view text) : pool_(pool), text_(text) {
    if (text.size() >= std::numeric_limits<std::uint32_t>::max()) {
      throw SymbolicError("expression text of " + std::to_string(text.size()) +
                          " bytes: at most 4 GiB");
    }
    tokenize();
  }

  Expr parse_all() {
    if (tokens_.size() == 1) throw error("empty expression", tokens_[0]);
    return parse_expression();
  }

 private:
  SymbolicError error(const std::string& what, const Token& at) const {
    return SymbolicError(what + " at column " + std::to_string(at.column()) + " in '" +
                         std::string(text_) + "'");
  }

  std::string_view text(const Token& token) const {
    return text_.substr(token.start, token.length);
  }

  void add(Token::Kind kind, char symbol, std::size_t start, std::size_t end) {
    tokens_.push_back(
        {kind, symbol, static_cast<std::uint32_t>(start), static_cast<std::uint32_t>(end - start)});
  }

  void tokenize() {
    std::size_t i = 0;
    while (i < text_.size()) {
      const auto c = static_cast<unsigned char>(text_[i]);
      const std::size_t start = i;
      if (std::isspace(c)) {
        ++i;
      } else if (std::isdigit(c) || (c == '.' && i + 1 < text_.size() &&
                                     std::isdigit(static_cast<unsigned char>(text_[i + 1])))) {
        while (i < text_.size() &&
               (std::isdigit(static_cast<unsigned char>(text_[i])) || text_[i] == '.')) {
          ++i;
        }
        if (i < text_.size() && (text_[i] == 'e' || text_[i] == 'E')) {
          std::size_t j = i + 1;
          if (j < text_.size() && (text_[j] == '+' || text_[j] == '-')) ++j;
          if (j < text_.size() && std::isdigit(static_cast<unsigned char>(text_[j]))) {
            i = j;
            while (i < text_.size() && std::isdigit(static_cast<unsigned char>(text_[i]))) ++i;
          }
        }
        add(Token::kNumber, 0, start, i);
      } else if (c >= 0x80) {
        throw SymbolicError(non_ascii_message(text_, start));
      } else if (std::isalpha(c) || c == '_') {
        while (i < text_.size() &&
               (std::isalnum(static_cast<unsigned char>(text_[i])) || text_[i] == '_')) {
          ++i;
        }
        add(Token::kName, 0, start, i);
      } else if (c == '*' && i + 1 < text_.size() && text_[i + 1] == '*') {
        i += 2;
        add(Token::kSymbol, '^', start, i);
      } else if (std::string_view("+-*/^(),").find(static_cast<char>(c)) !=
                 std::string_view::npos) {
        ++i;
        add(Token::kSymbol, static_cast<char>(c), start, i);
      } else {
        throw SymbolicError("unexpected character '" + std::string(1, static_cast<char>(c)) +
                            "' at column " + std::to_string(start + 1) + " in '" +
                            std::string(text_) + "'");
      }
    }
    add(Token::kEnd, 0, text_.size(), text_.size());
  }

  // An operator waiting on the stack for its right operand (or, for brackets, its closing ')').
  struct Pending {
    enum Kind { kAdd, kSubtract, kMultiply, kDivide, kPower, kNegate, kPlus, kParen, kCall } kind;
    std::size_t token;     // index of its token (the name for a call), for error columns
    std::size_t operands;  // kCall: operand-stack size when its arguments began
  };

  // Binding strength of the operators still waiting (brackets never pop on precedence).
  static int precedence(Pending::Kind kind) {
    switch (kind) {
      case Pending::kAdd:
      case Pending::kSubtract:
        return 1;
      case Pending::kMultiply:
      case Pending::kDivide:
        return 2;
      case Pending::kNegate:
      case Pending::kPlus:
        return 3;  // -x*y = (-x)*y, -x^2 = -(x^2)
      case Pending::kPower:
        return 4;  // right-associative
      case Pending::kParen:
      case Pending::kCall:
        return 0;
    }
    return 0;
  }
  // Entries that count as a nesting level: brackets, signs and powers (whose right operands may
  // nest without bound); + - * / are reduced as soon as they can be.
  static bool nests(Pending::Kind kind) {
    return kind == Pending::kParen || kind == Pending::kCall || kind == Pending::kNegate ||
           kind == Pending::kPlus || kind == Pending::kPower;
  }

  static std::optional<Pending::Kind> binary_kind(const Token& token) {
    if (token.kind != Token::kSymbol) return std::nullopt;
    switch (token.symbol) {
      case '+':
        return Pending::kAdd;
      case '-':
        return Pending::kSubtract;
      case '*':
        return Pending::kMultiply;
      case '/':
        return Pending::kDivide;
      case '^':
        return Pending::kPower;
      default:
        return std::nullopt;
    }
  }

  bool is_symbol(const Token& token, char symbol) const {
    return token.kind == Token::kSymbol && token.symbol == symbol;
  }

  void push(Pending pending) {
    if (nests(pending.kind) && ++depth_ > kMaxParseDepth) {
      throw error("expression nested deeper than " + std::to_string(kMaxParseDepth) +
                      " levels (parentheses, function calls, signs and powers)",
                  tokens_[pending.token]);
    }
    pending_.push_back(pending);
  }

  // An operand, or a sum or product still collecting its terms: `a + b - c + ...` and
  // `a * b / c * ...` become one n-ary node when the operand is used, never a chain of partial
  // sums (each interned in the pool for good: memory quadratic in the chain up to the flattening
  // limit).
  struct Operand {
    Expr expr;                  // when terms is empty
    std::vector<Term> terms{};  // coefficients (sum) or exponents (product) of +1 / -1
    bool product{false};
  };

  Expr value(Operand& operand) {
    if (operand.terms.empty()) return operand.expr;
    return operand.product ? pool_.product(Number::integer(1), operand.terms)
                           : pool_.sum(Number(), operand.terms);
  }

  Expr pop_operand() {
    Expr e = value(operands_.back());
    operands_.pop_back();
    return e;
  }

  // left (on top of the stack) op= right, collecting into an n-ary sum or product.
  void collect(bool product, Expr right, bool inverse) {
    Operand& left = operands_.back();
    if (left.terms.empty() || left.product != product) {
      const Expr first = value(left);
      left = Operand{{}, {{first, Number::integer(1)}}, product};
    }
    left.terms.push_back({right, Number::integer(inverse ? -1 : 1)});
  }

  // Applies the operator on top of the stack to its operands.
  void reduce() {
    const Pending top = pending_.back();
    pending_.pop_back();
    if (nests(top.kind)) --depth_;
    if (top.kind == Pending::kNegate) {
      const Expr negated = -pop_operand();
      operands_.push_back({negated});
      return;
    }
    if (top.kind == Pending::kPlus) return;
    const Expr right = pop_operand();
    switch (top.kind) {
      case Pending::kAdd:
      case Pending::kSubtract:
        collect(false, right, top.kind == Pending::kSubtract);
        break;
      case Pending::kMultiply:
        collect(true, right, false);
        break;
      case Pending::kDivide:
        if (right.is_constant() && right.constant().is_zero()) {
          throw error("division by zero", tokens_[top.token]);
        }
        collect(true, right, true);
        break;
      default: {  // kPower
        const Expr left = pop_operand();
        if (left.is_constant() && left.constant().is_zero() && right.is_constant() &&
            right.constant().is_negative()) {
          throw error("0 raised to a negative power", tokens_[top.token + 1]);
        }
        operands_.push_back({pow(left, right)});
        break;
      }
    }
  }

  // Reduces while the operator on top binds at least as tightly as `kind` (more tightly for the
  // right-associative ^), and never past a bracket.
  void reduce_before(Pending::Kind kind) {
    const int p = precedence(kind);
    while (!pending_.empty() && !is_bracket(pending_.back().kind)) {
      const int top = precedence(pending_.back().kind);
      if (top < p || (kind == Pending::kPower && top == p)) break;
      reduce();
    }
  }
  static bool is_bracket(Pending::Kind kind) {
    return kind == Pending::kParen || kind == Pending::kCall;
  }
  // Reduces down to the innermost bracket; false if there is none.
  bool reduce_to_bracket() {
    while (!pending_.empty() && !is_bracket(pending_.back().kind)) reduce();
    return !pending_.empty();
  }

  // Operator precedence with explicit stacks (no recursion: any nesting up to kMaxParseDepth
  // costs heap, not C++ stack). Two states: expecting an operand, or an operator after one.
  Expr parse_expression() {
    bool operand_expected = true;
    std::size_t i = 0;
    while (true) {
      const Token& token = tokens_[i];
      if (operand_expected) {
        if (token.kind == Token::kNumber) {
          const auto number = Number::parse_decimal(text(token));
          if (!number) throw error("malformed number '" + std::string(text(token)) + "'", token);
          operands_.push_back({pool_.constant(*number)});
          operand_expected = false;
        } else if (token.kind == Token::kName) {
          if (is_symbol(tokens_[i + 1], '(')) {
            push({Pending::kCall, i, operands_.size()});
            ++i;                                   // the '('
            if (is_symbol(tokens_[i + 1], ')')) {  // no arguments
              ++i;
              finish_call();
              operand_expected = false;
            }
          } else {
            operands_.push_back({name(token)});
            operand_expected = false;
          }
        } else if (is_symbol(token, '(')) {
          push({Pending::kParen, i, 0});
        } else if (is_symbol(token, '-')) {
          push({Pending::kNegate, i, 0});
        } else if (is_symbol(token, '+')) {
          push({Pending::kPlus, i, 0});
        } else {
          throw error(token.kind == Token::kEnd ? "unexpected end of input"
                                                : "unexpected '" + std::string(text(token)) + "'",
                      token);
        }
        ++i;
        continue;
      }
      // An operand was just read: a binary operator, ')', ',' or the end.
      if (const auto kind = binary_kind(token)) {
        reduce_before(*kind);
        push({*kind, i, 0});
        operand_expected = true;
      } else if (is_symbol(token, ')') || is_symbol(token, ',')) {
        if (!reduce_to_bracket() ||
            (is_symbol(token, ',') && pending_.back().kind != Pending::kCall)) {
          throw error("unexpected '" + std::string(text(token)) + "'", token);
        }
        if (is_symbol(token, ')')) {
          if (pending_.back().kind == Pending::kCall) {
            finish_call();
          } else {
            pending_.pop_back();
            --depth_;
            // The group is one operand: "(a*b)*c" builds a*b, then multiplies it by c, as the tree
            // reads (not one product of a, b and c, which differs if a*b is too long to flatten).
            operands_.back() = {value(operands_.back())};
          }
        } else {
          operand_expected = true;  // the next argument
        }
      } else {
        reduce_to_bracket();
        if (!pending_.empty()) throw error("expected ')'", token);
        if (token.kind != Token::kEnd)
          throw error("unexpected '" + std::string(text(token)) + "'", token);
        return pop_operand();
      }
      ++i;
    }
  }

  Expr name(const Token& token) {
    if (text(token) == "pi") {
      // A 17-digit literal is a one-ulp enclosure of the nearest double (M_PI, just below π), so
      // it contains π; it is also exactly what printing this constant produces.
      return pool_.constant(*Number::parse_decimal("3.1415926535897931"));
    }
    return pool_.variable(text(token));
  }

  // The call on top of the stack has all its arguments on the operand stack: apply it.
  void finish_call() {
    const Pending call = pending_.back();
    pending_.pop_back();
    --depth_;
    const Token& name = tokens_[call.token];
    std::vector<Expr> args;
    for (std::size_t k = call.operands; k < operands_.size(); ++k) {
      args.push_back(value(operands_[k]));
    }
    operands_.resize(call.operands);
    std::string fn(text(name));
    if (fn == "fabs") fn = "abs";
    if (fn == "fmin") fn = "min";
    if (fn == "fmax") fn = "max";
    auto arity = [&](std::size_t n) {
      if (args.size() != n) {
        throw error("'" + std::string(text(name)) + "' takes " + std::to_string(n) + " argument" +
                        (n == 1 ? "" : "s") + ", got " + std::to_string(args.size()),
                    name);
      }
    };
    if (fn == "pow") {
      arity(2);
      operands_.push_back({pow(args[0], args[1])});
      return;
    }
    for (const Op op : kFunctionOps) {
      if (function_name(op) != fn) continue;
      if (is_unary_function(op)) {
        arity(1);
        operands_.push_back({pool_.function(op, args[0])});
      } else {
        arity(2);
        operands_.push_back({pool_.function(op, args[0], args[1])});
      }
      return;
    }
    throw error("unknown function '" + std::string(text(name)) + "'", name);
  }

  ExprPool& pool_;
  std::string_view text_;
  std::vector<Token> tokens_;
  std::vector<Operand> operands_;
  std::vector<Pending> pending_;
  int depth_ = 0;  // entries of pending_ that nest (see nests())
};

// Printing precedence: how tightly a printed form binds.
enum Precedence { kSum = 1, kProduct = 2, kPower = 3, kAtom = 4 };

Precedence number_precedence(const Number& n) {
  if (n.is_negative()) return kSum;  // "-2" must be parenthesised after an operator
  if (n.is_rational() && n.to_string().find('/') != std::string::npos) return kProduct;
  return kAtom;
}

// How a node prints, as a layout: literal text interleaved with references to its operands'
// layouts. Storing layouts instead of finished strings keeps printing linear in the output: a
// chain n deep would otherwise hold n strings of growing length (quadratic memory).
struct Piece {
  std::string text;        // literal text (when !is_child)
  std::uint32_t child{0};  // operand id (when is_child)
  bool is_child{false};
  bool parens{false};  // wrap the child's text in parentheses
};

struct Layout {
  std::vector<Piece> pieces;
  Precedence precedence{kAtom};
  // The layout is a product whose first factor is a parenthesised sum. A coefficient printed in
  // front of it ("3*" or a unary "-") must group the whole product, or re-parsing would
  // distribute the coefficient into that sum and build a different node.
  bool starts_with_sum{false};

  void text(std::string s) {
    if (!pieces.empty() && !pieces.back().is_child) {
      pieces.back().text += s;
    } else {
      pieces.push_back({std::move(s), 0, false, false});
    }
  }
  void child(Expr e, bool parens) { pieces.push_back({{}, e.id(), true, parens}); }
  void append(const Layout& other) {
    for (const Piece& p : other.pieces) p.is_child ? pieces.push_back(p) : text(p.text);
  }
};

// Each node's layout, by node id.
using Layouts = std::unordered_map<std::uint32_t, Layout>;

std::string number_text(const Number& n, Precedence needed) {
  std::string text = n.to_string();
  if (number_precedence(n) < needed) text.insert(0, 1, '(').push_back(')');
  return text;
}

// Writes the tree text of `root` from the layouts with an explicit stack (any depth).
std::string emit(Expr root, const Layouts& layouts) {
  struct Frame {
    const Layout* layout;
    std::size_t next;
    bool close;  // write ")" when done
  };
  std::string out;
  std::vector<Frame> stack{{&layouts.at(root.id()), 0, false}};
  while (!stack.empty()) {
    Frame& top = stack.back();
    if (top.next == top.layout->pieces.size()) {
      if (top.close) out += ')';
      stack.pop_back();
      continue;
    }
    const Piece& piece = top.layout->pieces[top.next++];
    if (!piece.is_child) {
      out += piece.text;
      continue;
    }
    if (piece.parens) out += '(';
    stack.push_back({&layouts.at(piece.child), 0, piece.parens});
  }
  return out;
}

// c0 + Σ c_i t_i as "t1 - 2*t2 + 3", each term grouped as its precedence needs.
Layout sum_layout(Expr e, const Layouts& layouts) {
  Layout out;
  for (std::size_t i = 0; i < e.operand_count(); ++i) {
    const Number& c = e.factor(i);
    const Layout& term = layouts.at(e.operand(i).id());
    const bool negative = c.is_negative();
    const Number magnitude = negative ? -c : c;
    if (i > 0) {
      out.text(negative ? " - " : " + ");
    } else if (negative) {
      out.text("-");
    }
    // After "c*" or a leading unary "-", a product starting with a sum must be grouped.
    const bool prefixed = !magnitude.is_one() || (i == 0 && negative);
    if (!magnitude.is_one()) out.text(number_text(magnitude, kProduct) + "*");
    out.child(e.operand(i), (prefixed && term.starts_with_sum) || term.precedence < kProduct);
  }
  const Number& c0 = e.constant();
  if (!c0.is_zero())
    out.text((c0.is_negative() ? " - " : " + ") + (c0.is_negative() ? -c0 : c0).to_string());
  out.precedence = kSum;
  return out;
}

// c · Π b_i^e_i as "c*a*b^2/(d*f)" (or "/d/f" past the flattening limit), the sign in front.
Layout product_layout(Expr e, const Layouts& layouts) {
  Layout out;
  Layout numerator, denominator;
  std::size_t numerator_count = 0, denominator_count = 0;
  std::size_t first_numerator = e.operand_count();
  // A denominator of more factors than flattening takes prints as "/a/b/c...": grouped as
  // "/(a*b*c...)", it would re-parse as one product too long to flatten into this one.
  std::size_t inverse_count = 0;
  for (std::size_t i = 0; i < e.operand_count(); ++i) inverse_count += e.factor(i).is_negative();
  const bool divide_each = inverse_count > kFlattenLimit;
  for (std::size_t i = 0; i < e.operand_count(); ++i) {
    const Number& exponent = e.factor(i);
    const Layout& base = layouts.at(e.operand(i).id());
    const bool inverse = exponent.is_negative();
    const Number magnitude = inverse ? -exponent : exponent;
    Layout& side = inverse ? denominator : numerator;
    std::size_t& count = inverse ? denominator_count : numerator_count;
    if (!inverse && count == 0) first_numerator = i;
    if (count++ > 0) side.text(inverse && divide_each ? "/" : "*");
    if (magnitude.is_one()) {
      // A product that is a factor of a product was too long to flatten (expr.hpp): without
      // parentheses it would re-parse as factors of this product, a different node.
      side.child(e.operand(i), base.precedence < kProduct || e.operand(i).op() == Op::kMul);
    } else {
      side.child(e.operand(i), base.precedence < kAtom);
      side.text("^");
      side.text(number_text(magnitude, kAtom));
    }
  }
  Layout rest = numerator;
  if (denominator_count > 0) {
    const bool grouped = denominator_count > 1 && !divide_each;
    rest.text("/");
    if (grouped) rest.text("(");
    rest.append(denominator);
    if (grouped) rest.text(")");
  }
  const bool starts_with_sum = numerator_count > 0 && e.operand(first_numerator).op() == Op::kAdd;
  const Number& c = e.constant();
  const bool negative = c.is_negative();
  const Number magnitude = negative ? -c : c;
  if (negative) out.text("-");
  if (!magnitude.is_one() || numerator_count == 0) {
    out.text(number_text(magnitude, kProduct));
    if (numerator_count > 0) out.text("*");
  }
  const bool grouped = (negative || !magnitude.is_one()) && starts_with_sum;
  if (grouped) out.text("(");
  out.append(rest);
  if (grouped) out.text(")");
  const bool single_power =
      !negative && magnitude.is_one() && numerator_count == 1 && denominator_count == 0;
  out.precedence = negative ? kSum : (single_power ? kPower : kProduct);
  out.starts_with_sum = !negative && magnitude.is_one() && starts_with_sum;
  return out;
}

}  // namespace

Expr parse(ExprPool& pool, std::string_view text) { return Parser(pool, text).parse_all(); }

std::string to_string(Expr root, double max_tree_nodes) {
  const double size = tree_size(root);
  if (size > max_tree_nodes) {
    throw SymbolicError("expression too large to print as text: " + std::to_string(size) +
                        " nodes as a tree (" + std::to_string(dag_size(root)) + " as a DAG)");
  }
  Layouts layouts;
  auto get = [&](Expr e) -> const Layout& { return layouts.at(e.id()); };
  for (Expr e : topological_order(std::span<const Expr>(&root, 1))) {
    Layout out;
    switch (e.op()) {
      case Op::kConstant:
        out.text(e.constant().to_string());
        out.precedence = number_precedence(e.constant());
        break;
      case Op::kVariable:
        out.text(e.name());
        break;
      case Op::kAdd:
        out = sum_layout(e, layouts);
        break;
      case Op::kMul:
        out = product_layout(e, layouts);
        break;
      case Op::kPow:
        out.child(e.operand(0), get(e.operand(0)).precedence < kAtom);
        out.text("^");
        out.child(e.operand(1), get(e.operand(1)).precedence < kAtom);
        out.precedence = kPower;
        break;
      default:
        out.text(std::string(function_name(e.op())) + "(");
        out.child(e.operand(0), false);
        if (e.operand_count() == 2) {
          out.text(", ");
          out.child(e.operand(1), false);
        }
        out.text(")");
    }
    layouts.emplace(e.id(), std::move(out));
  }
  return emit(root, layouts);
}

}  // namespace spar::symbolic

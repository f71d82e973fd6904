#include "symbolic/parse.hpp"

#include <cctype>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "symbolic/operations.hpp"

namespace spar::symbolic {
namespace {

struct Token {
  enum Kind { kNumber, kName, kSymbol, kEnd } kind;
  std::string text;
  std::size_t column;  // 1-based
};

class Parser {
 public:
  Parser(ExprPool& pool, std::string_view text) : pool_(pool), text_(text) { tokenize(); }

  Expr parse_all() {
    if (tokens_.size() == 1) throw error("empty expression", tokens_[0]);
    Expr e = parse_expr();
    if (peek().kind != Token::kEnd) throw error("unexpected '" + peek().text + "'", peek());
    return e;
  }

 private:
  SymbolicError error(const std::string& what, const Token& at) const {
    return SymbolicError(what + " at column " + std::to_string(at.column) + " in '" +
                         std::string(text_) + "'");
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
        tokens_.push_back({Token::kNumber, std::string(text_.substr(start, i - start)), start + 1});
      } else if (std::isalpha(c) || c == '_' || c >= 0x80) {
        while (i < text_.size() &&
               (std::isalnum(static_cast<unsigned char>(text_[i])) || text_[i] == '_' ||
                static_cast<unsigned char>(text_[i]) >= 0x80)) {
          ++i;
        }
        tokens_.push_back({Token::kName, std::string(text_.substr(start, i - start)), start + 1});
      } else if (c == '*' && i + 1 < text_.size() && text_[i + 1] == '*') {
        i += 2;
        tokens_.push_back({Token::kSymbol, "^", start + 1});
      } else if (std::string_view("+-*/^(),").find(static_cast<char>(c)) !=
                 std::string_view::npos) {
        ++i;
        tokens_.push_back({Token::kSymbol, std::string(1, static_cast<char>(c)), start + 1});
      } else {
        throw SymbolicError("unexpected character '" + std::string(1, static_cast<char>(c)) +
                            "' at column " + std::to_string(start + 1) + " in '" +
                            std::string(text_) + "'");
      }
    }
    tokens_.push_back({Token::kEnd, "end of input", text_.size() + 1});
  }

  const Token& peek() const { return tokens_[position_]; }
  bool accept(std::string_view symbol) {
    if (peek().kind == Token::kSymbol && peek().text == symbol) {
      ++position_;
      return true;
    }
    return false;
  }
  void expect(std::string_view symbol) {
    if (!accept(symbol)) throw error("expected '" + std::string(symbol) + "'", peek());
  }

  // Counts nesting so that hostile input fails cleanly instead of overflowing the stack.
  struct DepthGuard {
    explicit DepthGuard(Parser& p) : parser(p) {
      if (++parser.depth_ > kMaxParseDepth) {
        throw parser.error(
            "expression nested deeper than " + std::to_string(kMaxParseDepth) + " levels",
            parser.peek());
      }
    }
    ~DepthGuard() { --parser.depth_; }
    Parser& parser;
  };

  Expr parse_expr() {
    DepthGuard guard(*this);
    Expr e = parse_term();
    while (true) {
      if (accept("+")) {
        e = e + parse_term();
      } else if (accept("-")) {
        e = e - parse_term();
      } else {
        return e;
      }
    }
  }

  Expr parse_term() {
    Expr e = parse_unary();
    while (true) {
      if (accept("*")) {
        e = e * parse_unary();
      } else if (peek().kind == Token::kSymbol && peek().text == "/") {
        const Token slash = peek();
        ++position_;
        const Expr divisor = parse_unary();
        if (divisor.is_constant() && divisor.constant().is_zero()) {
          throw error("division by zero", slash);
        }
        e = e / divisor;
      } else {
        return e;
      }
    }
  }

  Expr parse_unary() {
    DepthGuard guard(*this);
    if (accept("-")) return -parse_unary();
    if (accept("+")) return parse_unary();
    return parse_power();
  }

  Expr parse_power() {
    const Expr base = parse_primary();
    if (!accept("^")) return base;
    const Token& at = peek();
    const Expr exponent = parse_unary();
    if (base.is_constant() && base.constant().is_zero() && exponent.is_constant() &&
        exponent.constant().is_negative()) {
      throw error("0 raised to a negative power", at);
    }
    return pow(base, exponent);
  }

  Expr parse_primary() {
    const Token token = peek();
    if (token.kind == Token::kNumber) {
      ++position_;
      const auto number = Number::parse_decimal(token.text);
      if (!number) throw error("malformed number '" + token.text + "'", token);
      return pool_.constant(*number);
    }
    if (token.kind == Token::kName) {
      ++position_;
      if (accept("(")) return parse_call(token);
      if (token.text == "pi") {
        // A 17-digit literal is a one-ulp enclosure of the nearest double (M_PI, just below π),
        // so it contains π; it is also exactly what printing this constant produces.
        return pool_.constant(*Number::parse_decimal("3.1415926535897931"));
      }
      return pool_.variable(token.text);
    }
    if (accept("(")) {
      const Expr e = parse_expr();
      expect(")");
      return e;
    }
    throw error(
        token.kind == Token::kEnd ? "unexpected end of input" : "unexpected '" + token.text + "'",
        token);
  }

  Expr parse_call(const Token& name) {
    std::vector<Expr> args;
    if (!accept(")")) {
      args.push_back(parse_expr());
      while (accept(",")) args.push_back(parse_expr());
      expect(")");
    }
    std::string fn = name.text;
    if (fn == "fabs") fn = "abs";
    if (fn == "fmin") fn = "min";
    if (fn == "fmax") fn = "max";
    auto arity = [&](std::size_t n) {
      if (args.size() != n) {
        throw error("'" + name.text + "' takes " + std::to_string(n) + " argument" +
                        (n == 1 ? "" : "s") + ", got " + std::to_string(args.size()),
                    name);
      }
    };
    if (fn == "pow") {
      arity(2);
      return pow(args[0], args[1]);
    }
    for (Op op = Op::kSin; op <= Op::kMax; op = static_cast<Op>(static_cast<int>(op) + 1)) {
      if (function_name(op) != fn) continue;
      if (is_unary_function(op)) {
        arity(1);
        return pool_.function(op, args[0]);
      }
      arity(2);
      return pool_.function(op, args[0], args[1]);
    }
    throw error("unknown function '" + name.text + "'", name);
  }

  ExprPool& pool_;
  std::string_view text_;
  std::vector<Token> tokens_;
  std::size_t position_ = 0;
  int depth_ = 0;
};

// Printing precedence: how tightly a printed form binds.
enum Precedence { kSum = 1, kProduct = 2, kPower = 3, kAtom = 4 };

Precedence number_precedence(const Number& n) {
  if (n.is_negative()) return kSum;  // "-2" must be parenthesised after an operator
  if (n.is_rational() && n.to_string().find('/') != std::string::npos) return kProduct;
  return kAtom;
}

struct Printed {
  std::string text;
  Precedence precedence;
  // The text is a product whose first factor is a parenthesised sum. A coefficient printed in
  // front of it ("3*" or a unary "-") must group the whole product, or re-parsing would
  // distribute the coefficient into that sum and build a different node.
  bool starts_with_sum = false;
};

std::string wrap(const Printed& p, Precedence needed) {
  return p.precedence < needed ? "(" + p.text + ")" : p.text;
}

}  // namespace

Expr parse(ExprPool& pool, std::string_view text) { return Parser(pool, text).parse_all(); }

std::string to_string(Expr root, double max_tree_nodes) {
  const double size = tree_size(root);
  if (size > max_tree_nodes) {
    throw SymbolicError("expression too large to print as text: " + std::to_string(size) +
                        " nodes as a tree (" + std::to_string(dag_size(root)) + " as a DAG)");
  }
  std::unordered_map<std::uint32_t, Printed> printed;
  auto get = [&](Expr e) -> const Printed& { return printed.at(e.id()); };
  for (Expr e : topological_order(std::span<const Expr>(&root, 1))) {
    Printed out;
    switch (e.op()) {
      case Op::kConstant:
        out = {e.constant().to_string(), number_precedence(e.constant())};
        break;
      case Op::kVariable:
        out = {e.name(), kAtom};
        break;
      case Op::kAdd: {
        std::string s;
        for (std::size_t i = 0; i < e.operand_count(); ++i) {
          const Number& c = e.factor(i);
          const Printed& term = get(e.operand(i));
          const bool negative = c.is_negative();
          const Number magnitude = negative ? -c : c;
          if (i > 0) {
            s += negative ? " - " : " + ";
          } else if (negative) {
            s += "-";
          }
          // After "c*" or a leading unary "-", a product starting with a sum must be grouped.
          const bool prefixed = !magnitude.is_one() || (i == 0 && negative);
          if (!magnitude.is_one()) {
            s += wrap({magnitude.to_string(), number_precedence(magnitude)}, kProduct) + "*";
          }
          s += prefixed && term.starts_with_sum ? "(" + term.text + ")" : wrap(term, kProduct);
        }
        const Number& c0 = e.constant();
        if (!c0.is_zero())
          s += (c0.is_negative() ? " - " : " + ") + (c0.is_negative() ? -c0 : c0).to_string();
        out = {s, kSum};
        break;
      }
      case Op::kMul: {
        std::vector<std::string> numerator, denominator;
        std::size_t first_numerator = e.operand_count();
        for (std::size_t i = 0; i < e.operand_count(); ++i) {
          const Number& exponent = e.factor(i);
          const Printed& base = get(e.operand(i));
          const bool inverse = exponent.is_negative();
          const Number magnitude = inverse ? -exponent : exponent;
          std::string factor =
              magnitude.is_one()
                  ? wrap(base, kProduct)
                  : wrap(base, kAtom) + "^" +
                        wrap({magnitude.to_string(), number_precedence(magnitude)}, kAtom);
          if (!inverse && numerator.empty()) first_numerator = i;
          (inverse ? denominator : numerator).push_back(factor);
        }
        std::string rest;
        for (std::size_t i = 0; i < numerator.size(); ++i) rest += (i ? "*" : "") + numerator[i];
        if (!denominator.empty()) {
          std::string d;
          for (std::size_t i = 0; i < denominator.size(); ++i) d += (i ? "*" : "") + denominator[i];
          rest += "/" + (denominator.size() > 1 ? "(" + d + ")" : d);
        }
        const bool starts_with_sum =
            !numerator.empty() && e.operand(first_numerator).op() == Op::kAdd;
        const Number& c = e.constant();
        const bool negative = c.is_negative();
        const Number magnitude = negative ? -c : c;
        std::string s = negative ? "-" : "";
        if (!magnitude.is_one() || numerator.empty()) {
          s += wrap({magnitude.to_string(), number_precedence(magnitude)}, kProduct);
          if (!numerator.empty()) s += "*";
        }
        const bool grouped = (negative || !magnitude.is_one()) && starts_with_sum;
        s += grouped ? "(" + rest + ")" : rest;
        const bool single_power =
            !negative && magnitude.is_one() && numerator.size() == 1 && denominator.empty();
        out = {s, negative ? kSum : (single_power ? kPower : kProduct),
               !negative && magnitude.is_one() && starts_with_sum};
        break;
      }
      case Op::kPow:
        out = {wrap(get(e.operand(0)), kAtom) + "^" + wrap(get(e.operand(1)), kAtom), kPower};
        break;
      default: {
        std::string s = std::string(function_name(e.op())) + "(" + get(e.operand(0)).text;
        if (e.operand_count() == 2) s += ", " + get(e.operand(1)).text;
        out = {s + ")", kAtom};
      }
    }
    printed.emplace(e.id(), std::move(out));
  }
  return printed.at(root.id()).text;
}

}  // namespace spar::symbolic

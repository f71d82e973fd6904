#include "spar/reports/json.hpp"

#include <cmath>
#include <string>
#include <type_traits>

#include "spar/reports/error.hpp"
#include "spar/reports/json_values.hpp"

namespace spar::reports {
namespace {

using Json = nlohmann::ordered_json;

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

// A record: a type with a static `fields(self, field)` list.
template <class T>
concept Record = requires(T& record) {
  T::fields(record, [](const char*, auto&) {});
};

// Every overload is a member, so each sees all the others whatever the order.
struct Writer {
  static Json write(double value) { return number_json(value); }
  static Json write(bool value) { return value; }
  static Json write(int value) { return value; }
  static Json write(std::size_t value) { return value; }
  static Json write(const std::string& value) { return value; }
  template <class T>
  static Json write(const Nullable<T>& value) {
    return value ? write(*value) : Json(nullptr);
  }
  template <class T, std::size_t N>
  static Json write(const std::array<T, N>& values) {
    Json out = Json::array();
    for (const T& value : values) out.push_back(write(value));
    return out;
  }
  template <class T>
  static Json write(const std::vector<T>& values) {
    Json out = Json::array();
    for (const T& value : values) out.push_back(write(value));
    return out;
  }
  template <class T>
  static Json write(const NamedValues<T>& values) {
    Json out = Json::object();
    for (const auto& [name, value] : values) out[name] = write(value);
    return out;
  }
  template <Record R>
  static Json write(const R& record) {
    Json out = Json::object();
    R::fields(record, [&out]<class M>(const char* key, const M& member) {
      if constexpr (IsOptional<M>::value) {
        if (member) out[key] = write(*member);
      } else {
        out[key] = write(member);
      }
    });
    return out;
  }
};

struct Reader {
  std::string what;  // "report", "bound record": for messages

  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw ReportError("malformed " + what + ": " + (path.empty() ? "the document" : path) + ": " +
                      problem);
  }

  void read(const Json& in, double& out, const std::string& path) const {
    if (in.is_number()) {
      out = in.get<double>();
      return;
    }
    if (in.is_string()) {
      const std::string& word = in.get_ref<const std::string&>();
      if (word == "inf" || word == "-inf" || word == "nan") {
        out = word == "nan" ? std::nan("") : word == "inf" ? HUGE_VAL : -HUGE_VAL;
        return;
      }
    }
    fail(path, "expected a number, got " + in.dump());
  }
  void read(const Json& in, bool& out, const std::string& path) const {
    if (!in.is_boolean()) fail(path, "expected true or false, got " + in.dump());
    out = in.get<bool>();
  }
  void read(const Json& in, int& out, const std::string& path) const {
    if (!in.is_number_integer()) fail(path, "expected an integer, got " + in.dump());
    out = in.get<int>();
  }
  void read(const Json& in, std::size_t& out, const std::string& path) const {
    if (!in.is_number_unsigned()) fail(path, "expected a count, got " + in.dump());
    out = in.get<std::size_t>();
  }
  void read(const Json& in, std::string& out, const std::string& path) const {
    if (!in.is_string()) fail(path, "expected a string, got " + in.dump());
    out = in.get<std::string>();
  }
  template <class T>
  void read(const Json& in, Nullable<T>& out, const std::string& path) const {
    if (in.is_null()) {
      out.reset();
      return;
    }
    T value{};
    read(in, value, path);
    out = std::move(value);
  }
  template <class T, std::size_t N>
  void read(const Json& in, std::array<T, N>& out, const std::string& path) const {
    if (!in.is_array() || in.size() != N)
      fail(path, "expected an array of " + std::to_string(N) + ", got " + in.dump());
    for (std::size_t i = 0; i < N; ++i) read(in[i], out[i], path + "[" + std::to_string(i) + "]");
  }
  template <class T>
  void read(const Json& in, std::vector<T>& out, const std::string& path) const {
    if (!in.is_array()) fail(path, "expected an array");
    out.assign(in.size(), T{});
    for (std::size_t i = 0; i < in.size(); ++i)
      read(in[i], out[i], path + "[" + std::to_string(i) + "]");
  }
  template <class T>
  void read(const Json& in, NamedValues<T>& out, const std::string& path) const {
    if (!in.is_object()) fail(path, "expected an object");
    out.clear();
    for (const auto& [name, value] : in.items()) {
      out.emplace_back(name, T{});
      read(value, out.back().second, path + "." + name);
    }
  }
  template <Record R>
  void read(const Json& in, R& record, const std::string& path) const {
    if (!in.is_object()) fail(path, "expected an object");
    R::fields(record, [&]<class M>(const char* key, M& member) {
      const std::string at = path.empty() ? key : path + "." + key;
      const auto found = in.find(key);
      if constexpr (IsOptional<M>::value) {
        if (found == in.end()) {
          member.reset();
        } else {
          typename M::value_type value{};
          read(*found, value, at);
          member = std::move(value);
        }
      } else {
        if (found == in.end()) fail(at, "missing");
        read(*found, member, at);
      }
    });
  }
};

}  // namespace

Json to_json(const Report& report) { return Writer::write(report); }
Json to_json(const Chosen& chosen) { return Writer::write(chosen); }
Json to_json(const BoundRecord& record) { return Writer::write(record); }

Json to_json(const SensePlanRecord& record) { return Writer::write(record); }

Report report_from_json(const Json& document) {
  if (!document.is_object() || !document.contains("schema") || document["schema"] != kReportSchema)
    throw ReportError(std::string("not a ") + kReportSchema +
                      " report (its \"schema\" member must say so)");
  Report report;
  Reader{"report"}.read(document, report, "");
  return report;
}

BoundRecord bound_record_from_json(const Json& document) {
  BoundRecord record;
  Reader{"bound record"}.read(document, record, "");
  return record;
}

}  // namespace spar::reports

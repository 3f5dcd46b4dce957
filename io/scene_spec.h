// The builder the schema table (io/scene_schema_table.cpp) is written with: one Spec per
// key, reading like the documentation, binding the struct field the value fills.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <typeindex>
#include <utility>
#include <vector>

#include "io/scene_map_reader.h"
#include "io/scene_schema.h"
#include "sim/scene/scene_words.h"

namespace shellmpm::scenefile {

namespace detail {
template <class T>
struct is_optional_enum : std::false_type {};
template <class E>
struct is_optional_enum<std::optional<E>> : std::is_enum<E> {};
}  // namespace detail

/// Builder for one KeySpec, so the schema table below reads like the documentation.
class Spec {
 public:
  Spec(std::string key, KeyType type) {
    k_.key = std::move(key);
    k_.type = type;
  }
  Spec& required() {
    k_.presence = Presence::Required;
    return *this;
  }
  Spec& def(std::string yaml) {
    k_.presence = Presence::Default;
    k_.default_value = std::move(yaml);
    return *this;
  }
  Spec& optional(std::string prose) {
    k_.presence = Presence::Optional;
    k_.default_value = std::move(prose);
    return *this;
  }
  Spec& unit(std::string u) {
    k_.unit = std::move(u);
    return *this;
  }
  Spec& gt(double v) { return lower(v, true); }
  Spec& ge(double v) { return lower(v, false); }
  Spec& lt(double v) { return upper(v, true); }
  Spec& le(double v) { return upper(v, false); }
  Spec& choices(std::vector<std::string> c) {
    k_.choices = std::move(c);
    return *this;
  }
  Spec& only_for(std::vector<std::string> types) {
    k_.only_for = std::move(types);
    return *this;
  }
  Spec& nonempty() {
    k_.nonempty = true;
    return *this;
  }
  Spec& unit_vector() {
    k_.unit_vector = true;
    return *this;
  }
  Spec& rule(std::string r) {
    k_.rule = std::move(r);
    return *this;
  }
  Spec& color() {
    k_.color = true;
    return rule("linear RGB, each in [0, 1]");
  }
  /// Binds the struct field the value fills; an enum field's words (or an optional enum's)
  /// become the choices.
  template <class S, class F>
  Spec& to(F S::*field) {
    if constexpr (std::is_enum_v<F>) k_.choices = words_of<F>();
    if constexpr (detail::is_optional_enum<F>::value)
      k_.choices = words_of<typename F::value_type>();
    return bind<S>([field](MapReader& r, const std::string& name, S& s) { r.get(name, s.*field); },
                   [field](const S& a, const S& b) { return bool(a.*field == b.*field); });
  }
  /// Binds a frame range or an integer pair to two int fields (first, last / width, height).
  template <class S>
  Spec& to(int S::*first, int S::*second) {
    const bool range = k_.type == KeyType::FrameRange;
    return bind<S>(
        [=](MapReader& r, const std::string& name, S& s) {
          if (range) {
            std::tie(s.*first, s.*second) = r.frames(name);
          } else {
            const std::array<int, 2> v = r.int2(name);
            s.*first = v[0];
            s.*second = v[1];
          }
        },
        [=](const S& a, const S& b) { return a.*first == b.*first && a.*second == b.*second; });
  }
  operator KeySpec() const { return k_; }  // NOLINT: implicit by design (table syntax)

 private:
  template <class S, class Fill, class Same>
  Spec& bind(Fill fill, Same same) {
    k_.binding = std::make_shared<const FieldBinding>(
        FieldBinding{std::type_index(typeid(S)),
                     [fill](MapReader& r, const std::string& name, void* object) {
                       fill(r, name, *static_cast<S*>(object));
                     },
                     [same](const void* a, const void* b) {
                       return same(*static_cast<const S*>(a), *static_cast<const S*>(b));
                     }});
    return *this;
  }
  Spec& lower(double v, bool open) {
    k_.min = v;
    k_.min_open = open;
    return *this;
  }
  Spec& upper(double v, bool open) {
    k_.max = v;
    k_.max_open = open;
    return *this;
  }
  KeySpec k_;
};

/// Every key of the scene format, in document order (the table; scene_schema() keeps one).
std::vector<KeySpec> build_schema();

}  // namespace shellmpm::scenefile

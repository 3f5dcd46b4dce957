#include "io/scene_quality.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/scene/scene_words.h"

namespace shellmpm {

QualityPreset quality_preset(Quality q) {
  QualityPreset p;
  switch (q) {
    case Quality::Draft:
      p.dx_factor = 2;
      p.cfl = 0.6;
      p.quadrature_thickness = 2;
      p.particles_per_cell = 4;
      break;
    case Quality::Preview:
      p.dx_factor = std::sqrt(2.0);
      p.cfl = 0.45;
      p.quadrature_thickness = 2;
      break;
    case Quality::Production:
      break;
    case Quality::Final:
      p.dx_factor = 1 / std::sqrt(2.0);
      p.quadrature_thickness = 5;
      p.contact_samples = 3;
      break;
  }
  return p;
}

namespace scenefile {

namespace {

DocNode* entry(DocNode& map, const std::string& key) {
  if (map.kind != DocNode::Kind::Map) return nullptr;
  for (DocEntry& e : map.entries)
    if (e.key == key) return &e.value;
  return nullptr;
}

std::string text_of(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}

DocNode scalar(const std::string& text, const Origin& o) {
  DocNode n;
  n.kind = DocNode::Kind::Scalar;
  n.text = text;
  n.plain = true;
  n.origin = o;
  return n;
}

/// Sets map.key to `text` when the key is absent.
void set_if_absent(DocNode& map, const std::string& key, const std::string& text, const Origin& o) {
  if (map.kind != DocNode::Kind::Map || entry(map, key) != nullptr) return;
  map.entries.push_back({key, o, scalar(text, o)});
}

/// Multiplies a plain number in place (left alone when it is not one: the schema reports it).
void scale_number(DocNode* n, double factor) {
  if (n == nullptr || n->kind != DocNode::Kind::Scalar || !n->plain) return;
  char* end = nullptr;
  const double v = std::strtod(n->text.c_str(), &end);
  if (end == n->text.c_str() || *end != '\0' || !std::isfinite(v)) return;
  n->text = text_of(v * factor);
}

/// A sheet's or cylinder's resolution divided by the factor (rounded, at least `least`).
void scale_resolution(DocNode* res, double factor, int least_first) {
  if (res == nullptr || res->kind != DocNode::Kind::List) return;
  for (std::size_t i = 0; i < res->items.size(); ++i) {
    DocNode& n = res->items[i];
    if (n.kind != DocNode::Kind::Scalar || !n.plain) continue;
    char* end = nullptr;
    const long v = std::strtol(n.text.c_str(), &end, 10);
    if (end == n.text.c_str() || *end != '\0' || v < 1) continue;
    const long least = i == 0 ? least_first : 1;
    n.text = std::to_string(std::max<long>(least, std::lround(v / factor)));
  }
}

}  // namespace

void apply_quality(DocNode& root) {
  DocNode* shot = entry(root, "shot");
  if (shot == nullptr) return;
  const DocNode* q = entry(*shot, "quality");
  if (q == nullptr || q->kind != DocNode::Kind::Scalar) return;
  const std::optional<Quality> quality = enum_of_word<Quality>(q->text);
  if (!quality) return;
  const QualityPreset p = quality_preset(*quality);
  const Origin o = q->origin;

  scale_number(entry(*shot, "dx"), p.dx_factor);
  set_if_absent(*shot, "cfl", text_of(p.cfl), o);
  if (DocNode* mats = entry(root, "shell_materials"); mats && mats->kind == DocNode::Kind::List)
    for (DocNode& m : mats->items) {
      set_if_absent(m, "quadrature_inplane", std::to_string(p.quadrature_inplane), o);
      set_if_absent(m, "quadrature_thickness", std::to_string(p.quadrature_thickness), o);
      set_if_absent(m, "contact_samples", std::to_string(p.contact_samples), o);
    }
  if (DocNode* srcs = entry(root, "sources"); srcs && srcs->kind == DocNode::Kind::List)
    for (DocNode& s : srcs->items)
      set_if_absent(s, "particles_per_cell", text_of(p.particles_per_cell), o);
  if (DocNode* shells = entry(root, "shells"); shells && shells->kind == DocNode::Kind::List)
    for (DocNode& sh : shells->items) {
      DocNode* g = entry(sh, "geometry");
      if (g == nullptr) continue;
      const DocNode* type = entry(*g, "type");
      if (type == nullptr || type->kind != DocNode::Kind::Scalar) continue;
      if (type->text == "sheet") scale_resolution(entry(*g, "resolution"), p.dx_factor, 1);
      if (type->text == "cylinder") {
        const DocNode* angle = entry(*g, "angle");
        const bool closed = angle == nullptr || angle->text == "360";
        scale_resolution(entry(*g, "resolution"), p.dx_factor, closed ? 3 : 1);
      }
    }
}

}  // namespace scenefile
}  // namespace shellmpm

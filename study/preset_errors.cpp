#include "study/preset_errors.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/scene/scene_words.h"

namespace shellmpm {

std::vector<std::string> nearest_problems(const Scene& scene) {
  std::vector<std::string> out;
  bool contact_shells = false, lone_shells = false;
  for (const ShellDesc& s : scene.shells) {
    const bool contact =
        s.contact == ShellDesc::Contact::On ||
        (s.contact == ShellDesc::Contact::Auto &&
         (!scene.colliders.empty() || !scene.sources.empty() || scene.shells.size() > 1));
    (contact ? contact_shells : lone_shells) = true;
  }
  if (contact_shells) {
    out.push_back("incline_collider");
    out.push_back("incline_sheet");
    out.push_back("drape_sphere");
  }
  if (lone_shells) out.push_back("plate_simply_supported");
  bool sand = false, elastic = false;
  for (const SourceDesc& src : scene.sources) {
    const MaterialKind k = scene.materials.at(src.material).kind;
    (k == MaterialKind::Sand ? sand : elastic) = true;
  }
  if (sand) out.push_back("sand_column");
  if (elastic) out.push_back("bar_impact");
  return out;
}

std::vector<PresetMeasurement> preset_measurements(const std::string& results_json, Quality quality,
                                                   const std::vector<std::string>& problems) {
  std::vector<PresetMeasurement> out;
  std::ifstream in(results_json);
  if (!in) return out;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return out;
  }
  if (!j.is_object()) return out;
  const std::string label = std::string("quality=") + word_of(quality);
  for (const std::string& name : problems)
    for (const nlohmann::json& p : j.value("problems", nlohmann::json::array())) {
      if (!p.is_object() || p.value("name", "") != name) continue;
      const nlohmann::json* mine = nullptr;
      const nlohmann::json* production = nullptr;
      // value() returns a copy: kept here, since mine and production point into it (they
      // dangled when the copy was the loop's temporary, and `check --quality` read freed
      // memory).
      const nlohmann::json runs = p.value("runs", nlohmann::json::array());
      for (const nlohmann::json& r : runs) {
        if (!r.is_object() || r.value("sweep", "") != "quality preset" ||
            r.value("status", "") != "ok")
          continue;
        if (r.value("label", "") == label) mine = &r;
        if (r.value("label", "") == "quality=production") production = &r;
      }
      if (mine == nullptr || !mine->contains("error") || !(*mine)["error"].is_number()) continue;
      PresetMeasurement m;
      m.problem = name;
      std::ostringstream e;
      e.precision(3);
      const double err = (*mine)["error"].get<double>();
      if (p.value("error_kind", "") == "relative")
        e << std::showpos << 100 * err << "%";
      else
        e << std::showpos << err << " " << p.value("unit", "");
      m.error = e.str();
      const double cost = mine->value("cost", 0.0);
      const double cost_production = production ? production->value("cost", 0.0) : 0.0;
      if (cost > 0 && cost_production > 0) m.cost_vs_production = cost / cost_production;
      out.push_back(m);
    }
  return out;
}

}  // namespace shellmpm

#include "study/quantity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "io/user_error.h"

namespace shellmpm {

namespace {

std::vector<std::string> split_dots(const std::string& s) {
  std::vector<std::string> parts;
  std::string cur;
  for (char c : s) {
    if (c == '.') {
      parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  parts.push_back(cur);
  return parts;
}

int axis_of(const std::string& s) {
  return s == "x" ? 0 : s == "y" ? 1 : s == "z" ? 2 : -1;
}

[[noreturn]] void bad(const std::string& where, const std::string& text, const std::string& why) {
  throw UserError(where + " " + text, 0, "", why);
}

const char* kForms =
    "expected shell.NAME.(lowest|highest|max_displacement|centroid.AXIS|vertex.I.AXIS), "
    "bulk.(centroid|max|min).AXIS or stats.KEY, optionally after max: or min:";

void parse_shell(const std::vector<std::string>& p, const Scene& scene, const std::string& where,
                 Quantity& q) {
  if (p.size() < 3) bad(where, q.text, kForms);
  q.source = Quantity::Source::Shell;
  q.shell = p[1];
  const auto it = std::find_if(scene.shells.begin(), scene.shells.end(),
                               [&](const ShellDesc& s) { return s.name == q.shell; });
  if (it == scene.shells.end()) {
    std::string names;
    for (const ShellDesc& s : scene.shells) names += (names.empty() ? "" : ", ") + s.name;
    bad(where, q.text,
        "the scene has no shell '" + q.shell + "' (shells: " + (names.empty() ? "none" : names) +
            ")");
  }
  if (!it->write_mesh) bad(where, q.text, "shell '" + q.shell + "' has write_mesh: false");
  const std::string& w = p[2];
  if (w == "lowest" && p.size() == 3) {
    q.what = Quantity::What::Lowest;
  } else if (w == "highest" && p.size() == 3) {
    q.what = Quantity::What::Highest;
  } else if (w == "max_displacement" && p.size() == 3) {
    q.what = Quantity::What::MaxDisplacement;
  } else if (w == "centroid" && p.size() == 4 && axis_of(p[3]) >= 0) {
    q.what = Quantity::What::Centroid;
    q.axis = axis_of(p[3]);
  } else if (w == "vertex" && p.size() == 5 && axis_of(p[4]) >= 0) {
    q.what = Quantity::What::Vertex;
    q.axis = axis_of(p[4]);
    std::size_t used = 0;
    long idx = -1;
    try {
      idx = std::stol(p[3], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != p[3].size() || idx < 0 || idx > std::numeric_limits<int>::max())
      bad(where, q.text, "vertex index '" + p[3] + "' is not a non-negative integer");
    q.vertex = static_cast<int>(idx);
    if (it->output_refine > 0)
      bad(where, q.text, "vertex indices need output_refine 0 (the written mesh is refined)");
  } else {
    bad(where, q.text, kForms);
  }
}

}  // namespace

Quantity parse_quantity(const std::string& text, const Scene& scene, const std::string& where) {
  Quantity q;
  q.text = text;
  std::string body = text;
  if (body.rfind("max:", 0) == 0) {
    q.over = Quantity::Over::MaxOverFrames;
    body = body.substr(4);
  } else if (body.rfind("min:", 0) == 0) {
    q.over = Quantity::Over::MinOverFrames;
    body = body.substr(4);
  }
  const std::vector<std::string> p = split_dots(body);
  for (const std::string& s : p)
    if (s.empty()) bad(where, text, kForms);
  if (p[0] == "shell") {
    parse_shell(p, scene, where, q);
  } else if (p[0] == "bulk") {
    if (p.size() != 3 || axis_of(p[2]) < 0) bad(where, text, kForms);
    q.source = Quantity::Source::Bulk;
    q.axis = axis_of(p[2]);
    if (p[1] == "centroid")
      q.what = Quantity::What::Centroid;
    else if (p[1] == "max")
      q.what = Quantity::What::Max;
    else if (p[1] == "min")
      q.what = Quantity::What::Min;
    else
      bad(where, text, kForms);
    if (scene.sources.empty()) bad(where, text, "the scene has no bulk sources");
  } else if (p[0] == "stats") {
    if (p.size() < 2) bad(where, text, kForms);
    q.source = Quantity::Source::Stats;
    q.stats_path.assign(p.begin() + 1, p.end());
  } else {
    bad(where, text, kForms);
  }
  return q;
}

namespace {

double reduce_points(const Quantity& q, const std::vector<Vec3d>& pts, const std::string& what) {
  if (pts.empty()) throw std::runtime_error(what + ": no points");
  if (q.what == Quantity::What::Vertex) {
    if (q.vertex >= static_cast<int>(pts.size()))
      throw std::runtime_error(what + ": vertex " + std::to_string(q.vertex) + " past its " +
                               std::to_string(pts.size()) + " vertices");
    return pts[q.vertex][q.axis];
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0;
  for (const Vec3d& x : pts) {
    lo = std::min(lo, x[q.axis]);
    hi = std::max(hi, x[q.axis]);
    sum += x[q.axis];
  }
  switch (q.what) {
    case Quantity::What::Lowest:
    case Quantity::What::Min:
      return lo;
    case Quantity::What::Highest:
    case Quantity::What::Max:
      return hi;
    default:
      return sum / pts.size();
  }
}

double value_at(const Quantity& q, const RunFolder& run, int frame) {
  switch (q.source) {
    case Quantity::Source::Shell: {
      const std::vector<Vec3d> x = run.shell_vertices(q.shell, frame);
      if (q.what == Quantity::What::MaxDisplacement) {
        const std::vector<Vec3d> x0 = run.shell_vertices(q.shell, run.first_frame());
        if (x0.size() != x.size())
          throw std::runtime_error(run.dir() + ": shell '" + q.shell +
                                   "' changed its vertex count between frames");
        double d = 0;
        for (std::size_t i = 0; i < x.size(); ++i) d = std::max(d, (x[i] - x0[i]).norm());
        return d;
      }
      return reduce_points(q, x, run.dir() + ": shell '" + q.shell + "'");
    }
    case Quantity::Source::Bulk:
      return reduce_points(q, run.particles(frame), run.dir() + ": particles");
    case Quantity::Source::Stats: {
      const nlohmann::json* j = &run.frame_stats(frame);
      std::string path = "frame " + std::to_string(frame);
      for (const std::string& k : q.stats_path) {
        path += "." + k;
        if (!j->is_object() || !j->contains(k))
          throw std::runtime_error(run.dir() + "/stats.json: " + path +
                                   ": no such value (quantity " + q.text + ")");
        j = &(*j)[k];
      }
      if (!j->is_number())
        throw std::runtime_error(run.dir() + "/stats.json: " + path + ": not a number (quantity " +
                                 q.text + ")");
      return j->get<double>();
    }
  }
  return 0;
}

}  // namespace

double evaluate_quantity(const Quantity& q, const RunFolder& run, int frame) {
  if (q.over == Quantity::Over::Frame) return value_at(q, run, frame);
  double best = 0;
  bool first = true;
  for (const nlohmann::json& f : run.frames()) {
    const double v = value_at(q, run, f.at("frame").get<int>());
    if (first || (q.over == Quantity::Over::MaxOverFrames ? v > best : v < best)) best = v;
    first = false;
  }
  return best;
}

}  // namespace shellmpm

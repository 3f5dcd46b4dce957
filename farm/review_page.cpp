#include "farm/review_page.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '&')
      o += "&amp;";
    else if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '"')
      o += "&quot;";
    else
      o += c;
  }
  return o;
}

/// The task's still: contact_sheet.png, else its last preview.####.png, else "".
std::string still_image(const BatchTask& t) {
  const std::string sheet = t.output + "/contact_sheet.png";
  if (fs::exists(sheet)) return sheet;
  std::string last;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(t.output, ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("preview.", 0) == 0 && n.size() > 4 && n.substr(n.size() - 4) == ".png" &&
        n.find(".tmp.") == std::string::npos && n > fs::path(last).filename().string())
      last = e.path().string();
  }
  return last;
}

/// One series as an SVG polyline in the box [x0, x0 + w] x [y0, y0 + h].
std::string polyline(const std::vector<double>& v, double lo, double hi, const char* colour) {
  if (v.empty()) return "";
  const double x0 = 40, w = 250, y0 = 10, h = 110;
  std::string pts;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double x = x0 + (v.size() > 1 ? w * static_cast<double>(i) / (v.size() - 1) : w / 2);
    const double y = y0 + h - (hi > lo ? h * (v[i] - lo) / (hi - lo) : h / 2);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f,%.1f ", x, y);
    pts += buf;
  }
  return std::string("<polyline fill=\"none\" stroke-width=\"2\" stroke=\"") + colour +
         "\" points=\"" + pts + "\"/>";
}

std::string number_cell(const std::string& text) {
  return "<td data-v=\"" + html_escape(text) + "\">" + html_escape(text.empty() ? "-" : text) +
         "</td>";
}

const char* kStyle = R"(body{font-family:sans-serif;margin:16px;background:#1e1e1e;color:#ddd}
table{border-collapse:collapse}td,th{border:1px solid #555;padding:4px 6px;vertical-align:top;
font-size:13px}th{cursor:pointer;background:#333;position:sticky;top:0}th:hover{background:#444}
img.sheet{max-width:480px;display:block}video{max-width:360px;display:block}
tbody.task{border-top:3px solid #777}.media{display:flex;gap:12px;align-items:flex-start}
.failed{color:#f66}.done{color:#6c6}.none{color:#888;font-style:italic})";

const char* kScript = R"(function sortBy(col){const table=document.getElementById('wedges');
const bodies=[...table.tBodies];const th=table.tHead.rows[0].cells[col];
const dir=th.dataset.dir==='asc'?-1:1;[...table.tHead.rows[0].cells].forEach(h=>h.dataset.dir='');
th.dataset.dir=dir>0?'asc':'desc';const key=b=>b.rows[0].cells[col].dataset.v;
bodies.sort((a,b)=>{const x=key(a),y=key(b);const nx=Number(x),ny=Number(y);
if(x!==''&&y!==''&&!isNaN(nx)&&!isNaN(ny))return dir*(nx-ny);return dir*String(x).localeCompare(String(y));});
bodies.forEach(b=>table.appendChild(b));}
window.addEventListener('load',()=>{const imgs=[...document.images];
document.body.dataset.images=imgs.length;document.body.dataset.loaded=imgs.filter(i=>i.complete&&i.naturalWidth>0).length;
document.body.dataset.tasks=document.querySelectorAll('tbody.task').length;
document.getElementById('loadstate').textContent='images: '+document.body.dataset.loaded+' of '+imgs.length+' loaded';});)";

/// The contact sheet, the movie and the plot, side by side.
std::string media_row(const WedgeRow& r, std::size_t columns, double max_movie_bytes) {
  const BatchTask& t = *r.task;
  std::string s = "<tr class=\"media\"><td colspan=\"" + std::to_string(columns) +
                  "\"><div class=\"media\"><div>";
  const std::string still = still_image(t);
  if (!still.empty())
    s += "<img class=\"sheet\" alt=\"" + html_escape(t.id()) + "\" src=\"" +
         data_uri("image/png", read_bytes(still)) + "\">";
  else
    s += "<span class=\"none\">no preview</span>";
  s += "</td><td>";
  const std::string movie = t.output + "/preview.mp4";
  std::error_code ec;
  if (fs::exists(movie, ec)) {
    const double size = static_cast<double>(fs::file_size(movie, ec));
    const std::string src =
        size <= max_movie_bytes ? data_uri("video/mp4", read_bytes(movie)) : "file://" + movie;
    s += "<video controls loop muted preload=\"metadata\" src=\"" + src + "\"></video>";
  } else {
    s += "<span class=\"none\">no movie</span>";
  }
  return s + "</div><div>" + stats_plot_svg(r.frames) + "</div></div></td></tr>\n";
}

}  // namespace

std::string data_uri(const std::string& mime, const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out = "data:" + mime + ";base64,";
  out.reserve(out.size() + (bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string stats_plot_svg(const nlohmann::json& frames) {
  std::vector<double> ke, speed;
  int first = 0, last = 0;
  for (const nlohmann::json& f : frames) {
    ke.push_back(f.value("kinetic_energy", 0.0) + f.value("shell_kinetic_energy", 0.0));
    speed.push_back(f.value("max_speed", 0.0));
    if (first == 0) first = f.value("frame", 0);
    last = f.value("frame", 0);
  }
  if (ke.empty()) return "<span class=\"none\">no frames yet</span>";
  auto range = [](const std::vector<double>& v) {
    return std::make_pair(*std::min_element(v.begin(), v.end()),
                          *std::max_element(v.begin(), v.end()));
  };
  const auto [klo, khi] = range(ke);
  const auto [slo, shi] = range(speed);
  char legend[512];
  std::snprintf(legend, sizeof legend,
                "<text x=\"40\" y=\"138\" fill=\"#ccc\" font-size=\"10\">frames %d-%d</text>"
                "<text x=\"300\" y=\"20\" fill=\"#e8a33d\" font-size=\"10\">kinetic energy</text>"
                "<text x=\"300\" y=\"32\" fill=\"#e8a33d\" font-size=\"10\">%.3g..%.3g J</text>"
                "<text x=\"300\" y=\"50\" fill=\"#4fa3e0\" font-size=\"10\">max speed</text>"
                "<text x=\"300\" y=\"62\" fill=\"#4fa3e0\" font-size=\"10\">%.3g..%.3g m/s</text>",
                first, last, klo, khi, slo, shi);
  return "<svg class=\"plot\" xmlns=\"http://www.w3.org/2000/svg\" width=\"400\" height=\"145\">"
         "<rect x=\"40\" y=\"10\" width=\"250\" height=\"110\" fill=\"#262626\" stroke=\"#555\"/>" +
         polyline(ke, klo, khi, "#e8a33d") + polyline(speed, slo, shi, "#4fa3e0") + legend +
         "</svg>";
}

std::string review_page_html(const BatchSpec& b, const WedgeTable& t, double max_movie_bytes) {
  std::string h = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" +
                  html_escape("shellmpm batch " + b.name) + "</title><style>" + kStyle +
                  "</style><script>" + kScript + "</script></head><body>\n";
  h += "<h1>batch " + html_escape(b.name) + "</h1><p>" + html_escape(b.path) + " &middot; " +
       std::to_string(t.rows.size()) + " tasks &middot; <span id=\"loadstate\"></span></p>\n";
  h += "<table id=\"wedges\"><thead><tr>";
  std::vector<std::string> cols = {"task", "shot", "wedge"};
  cols.insert(cols.end(), t.value_keys.begin(), t.value_keys.end());
  cols.insert(cols.end(), {"state", "frames", "restarts", "wall s"});
  cols.insert(cols.end(), t.figure_names.begin(), t.figure_names.end());
  cols.insert(cols.end(), {"integrity"});
  for (std::size_t i = 0; i < cols.size(); ++i)
    h += "<th onclick=\"sortBy(" + std::to_string(i) + ")\">" + html_escape(cols[i]) + "</th>";
  h += "</tr></thead>\n";
  for (const WedgeRow& r : t.rows) {
    const BatchTask& task = *r.task;
    h += "<tbody class=\"task\" data-task=\"" + std::to_string(task.index) + "\"><tr>";
    h += number_cell(std::to_string(task.index)) + number_cell(task.shot) + number_cell(task.wedge);
    for (const std::string& v : r.values) h += number_cell(v);
    h += "<td data-v=\"" + r.state + "\" class=\"" + r.state + "\">" + r.state + "</td>";
    h += number_cell(std::to_string(r.frames_done));
    h += number_cell(r.status ? std::to_string(r.status->restarts()) : "0");
    h += number_cell(r.status ? figure_text(r.status->sim.wall_seconds) : "");
    for (double x : r.figures) h += number_cell(figure_text(x));
    h += "<td data-v=\"" + html_escape(r.integrity) + "\" class=\"" +
         (r.integrity.rfind("failed", 0) == 0 ? "failed" : "") + "\">" + html_escape(r.integrity) +
         "</td>";
    h += "</tr>\n" + media_row(r, cols.size(), max_movie_bytes) + "</tbody>\n";
  }
  h += "</table>\n</body></html>\n";
  return h;
}

}  // namespace shellmpm

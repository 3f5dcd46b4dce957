// The batch's review page (`batch collect`): one self-contained HTML file (no server, no
// network; images, movies and plots inlined as data URIs and SVG) with a row per task: its
// wedge values, state and figures, its contact sheet (or last preview frame), its preview
// movie and a plot of its per-frame statistics side by side. Clicking a column header
// sorts the rows by it (numbers as numbers), the way dailies are reviewed.
#pragma once
#include <string>

#include "farm/wedge_table.h"

namespace shellmpm {

/// The page's HTML. Movies larger than `max_movie_bytes` are linked, not inlined.
std::string review_page_html(const BatchSpec& b, const WedgeTable& t,
                             double max_movie_bytes = 32e6);

/// A per-frame plot of a task's statistics as inline SVG: kinetic energy and the largest
/// speed, each scaled to its own range (the ranges are printed), over the frames.
std::string stats_plot_svg(const nlohmann::json& frames);

/// "data:MIME;base64,...".
std::string data_uri(const std::string& mime, const std::string& bytes);

}  // namespace shellmpm

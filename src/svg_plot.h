// svg_plot: a self-contained log-log line plot as an SVG document (hand-written XML, no dependency) — used for
// error against time. Invariants: the output is well-formed XML (every label escaped, every attribute quoted);
// each series is exactly one <path> (plus a <circle> per point), nothing else in the document is a <path>;
// axes span whole decades and are labelled at decades; points with a non-positive or non-finite coordinate
// cannot be placed on log axes and are left out.
#pragma once

#include <string>
#include <vector>

namespace bl {

// One curve: points (x[i], y[i]) in order, drawn as a polyline with a marker per point.
struct plot_series {
  std::string label;
  std::vector<double> x, y;
};

// Options of a log-log plot. Sizes are SVG user units (pixels).
struct loglog_plot_params {
  std::string title;
  std::string x_label = "x", y_label = "y";
  int width = 760, height = 480;
  double guide_slope = -1;                          // a dashed guide line of this slope (0: none) through
  std::string guide_label = "slope \u2212" "1";      // the first point of the first series, and its legend
};

// The SVG document of the plot: decade grid and tick labels, axis labels, one coloured path per series in a
// distinct colour, the guide line, and a legend to the right of the plot area.
std::string loglog_plot_svg(const std::vector<plot_series>& series, const loglog_plot_params& params);

// The colour ("#rrggbb") of series i: ten well-separated colours, then hues spaced by the golden angle.
std::string plot_color(int i);

// Text escaped for XML character data and quoted attribute values (& < > " ').
std::string xml_escape(const std::string& text);

}  // namespace bl

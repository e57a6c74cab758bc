// svg_plot: log-log plot layout (plot area, decade axes, legend) and its SVG text. Coordinates are printed
// with two decimals in the C locale; the document is built in memory and returned whole.
#include "svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bl {

// Placement of the plot area in the document and the decade range of each axis (log10 units).
struct plot_frame {
  double left = 0, top = 0, right = 0, bottom = 0;
  int x0 = 0, x1 = 1, y0 = 0, y1 = 1;  // axes span 10^x0 .. 10^x1 and 10^y0 .. 10^y1
};

// Whether (x, y) can be placed on log axes.
static bool plottable(double x, double y) { return std::isfinite(x) && std::isfinite(y) && x > 0 && y > 0; }

// Number with two decimals.
static std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

// Document x of data value x (> 0).
static double map_x(const plot_frame& f, double x) {
  return f.left + (std::log10(x) - f.x0) / double(f.x1 - f.x0) * (f.right - f.left);
}

// Document y of data value y (> 0); larger values are higher up.
static double map_y(const plot_frame& f, double y) {
  return f.bottom - (std::log10(y) - f.y0) / double(f.y1 - f.y0) * (f.bottom - f.top);
}

// Whole decades [lo, hi] covering [vmin, vmax] (at least one decade; [0, 1] when nothing is plottable).
static void decade_range(double vmin, double vmax, int& lo, int& hi) {
  if (!(vmin > 0) || !(vmax >= vmin) || !std::isfinite(vmax)) {
    lo = 0, hi = 1;
    return;
  }
  // The small slack keeps exact powers of ten (whose log10 may round off by an ulp) on their own decade.
  lo = int(std::floor(std::log10(vmin) + 1e-9));
  hi = int(std::ceil(std::log10(vmax) - 1e-9));
  if (hi <= lo) hi = lo + 1;
}

// "10" with a raised exponent, as SVG text content (U+2212 for the minus sign).
static std::string decade_label(int e) {
  std::string exp = e < 0 ? "\xe2\x88\x92" + std::to_string(-e) : std::to_string(e);
  return "10<tspan dy=\"-7\" font-size=\"10\">" + exp + "</tspan>";
}

std::string xml_escape(const std::string& text) {
  std::string s;
  s.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': s += "&amp;"; break;
      case '<': s += "&lt;"; break;
      case '>': s += "&gt;"; break;
      case '"': s += "&quot;"; break;
      case '\'': s += "&apos;"; break;
      default:
        // Control characters other than tab and newline are not allowed in XML 1.0.
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t' || c == '\n') s += c;
    }
  }
  return s;
}

std::string plot_color(int i) {
  static const char* const base[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                     "#17becf", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"};
  if (i >= 0 && i < 10) return base[i];
  // Further series: hue advanced by the golden angle, fixed saturation and lightness (HSL 0.65, 0.45).
  double h = std::fmod(double(i) * 137.50776, 360.0) / 60.0, c = (1 - std::fabs(2 * 0.45 - 1)) * 0.65;
  double x = c * (1 - std::fabs(std::fmod(h, 2.0) - 1)), m = 0.45 - c / 2;
  double rgb[3] = {0, 0, 0};
  int sector = int(h) % 6;
  const int order[6][3] = {{0, 1, 2}, {1, 0, 2}, {1, 2, 0}, {2, 1, 0}, {2, 0, 1}, {0, 2, 1}};
  rgb[order[sector][0]] = c, rgb[order[sector][1]] = x;
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", int(std::lround((rgb[0] + m) * 255)),
                int(std::lround((rgb[1] + m) * 255)), int(std::lround((rgb[2] + m) * 255)));
  return buf;
}

// Grid lines, ticks and tick labels of both axes (decades labelled, 2..9 minor ticks when few decades).
static std::string axes_svg(const plot_frame& f) {
  std::string s = "<g font-family=\"sans-serif\" font-size=\"13\" fill=\"#222\">\n";
  int xdec = f.x1 - f.x0, ydec = f.y1 - f.y0;
  int xstep = std::max(1, (xdec + 9) / 10), ystep = std::max(1, (ydec + 7) / 8);
  for (int e = f.x0; e <= f.x1; e++) {
    double x = map_x(f, std::pow(10.0, e));
    s += "<line x1=\"" + num(x) + "\" y1=\"" + num(f.top) + "\" x2=\"" + num(x) + "\" y2=\"" + num(f.bottom) +
         "\" stroke=\"#ddd\" stroke-width=\"1\"/>\n";
    s += "<line x1=\"" + num(x) + "\" y1=\"" + num(f.bottom) + "\" x2=\"" + num(x) + "\" y2=\"" + num(f.bottom + 6) +
         "\" stroke=\"#222\" stroke-width=\"1\"/>\n";
    if ((e - f.x0) % xstep == 0)
      s += "<text x=\"" + num(x) + "\" y=\"" + num(f.bottom + 24) + "\" text-anchor=\"middle\">" + decade_label(e) +
           "</text>\n";
    for (int m = 2; m <= 9 && e < f.x1 && xdec <= 6; m++) {
      double xm = map_x(f, m * std::pow(10.0, e));
      s += "<line x1=\"" + num(xm) + "\" y1=\"" + num(f.bottom) + "\" x2=\"" + num(xm) + "\" y2=\"" +
           num(f.bottom + 3) + "\" stroke=\"#222\" stroke-width=\"1\"/>\n";
    }
  }
  for (int e = f.y0; e <= f.y1; e++) {
    double y = map_y(f, std::pow(10.0, e));
    s += "<line x1=\"" + num(f.left) + "\" y1=\"" + num(y) + "\" x2=\"" + num(f.right) + "\" y2=\"" + num(y) +
         "\" stroke=\"#ddd\" stroke-width=\"1\"/>\n";
    s += "<line x1=\"" + num(f.left - 6) + "\" y1=\"" + num(y) + "\" x2=\"" + num(f.left) + "\" y2=\"" + num(y) +
         "\" stroke=\"#222\" stroke-width=\"1\"/>\n";
    if ((e - f.y0) % ystep == 0)
      s += "<text x=\"" + num(f.left - 10) + "\" y=\"" + num(y + 5) + "\" text-anchor=\"end\">" + decade_label(e) +
           "</text>\n";
    for (int m = 2; m <= 9 && e < f.y1 && ydec <= 6; m++) {
      double ym = map_y(f, m * std::pow(10.0, e));
      s += "<line x1=\"" + num(f.left - 3) + "\" y1=\"" + num(ym) + "\" x2=\"" + num(f.left) + "\" y2=\"" + num(ym) +
           "\" stroke=\"#222\" stroke-width=\"1\"/>\n";
    }
  }
  s += "<rect x=\"" + num(f.left) + "\" y=\"" + num(f.top) + "\" width=\"" + num(f.right - f.left) + "\" height=\"" +
       num(f.bottom - f.top) + "\" fill=\"none\" stroke=\"#222\" stroke-width=\"1\"/>\n";
  s += "</g>\n";
  return s;
}

std::string loglog_plot_svg(const std::vector<plot_series>& series, const loglog_plot_params& params) {
  const double w = std::max(params.width, 320), h = std::max(params.height, 240);
  plot_frame f;
  f.left = 80, f.top = 44, f.right = w - 190, f.bottom = h - 60;
  double xmin = INFINITY, xmax = 0, ymin = INFINITY, ymax = 0;
  for (const plot_series& s : series)
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); i++)
      if (plottable(s.x[i], s.y[i])) {
        xmin = std::min(xmin, s.x[i]), xmax = std::max(xmax, s.x[i]);
        ymin = std::min(ymin, s.y[i]), ymax = std::max(ymax, s.y[i]);
      }
  decade_range(xmin, xmax, f.x0, f.x1);
  decade_range(ymin, ymax, f.y0, f.y1);

  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + num(w) + "\" height=\"" + num(h) +
       "\" viewBox=\"0 0 " + num(w) + " " + num(h) + "\">\n";
  s += "<title>" + xml_escape(params.title) + "</title>\n";
  s += "<defs><clipPath id=\"plot-area\"><rect x=\"" + num(f.left) + "\" y=\"" + num(f.top) + "\" width=\"" +
       num(f.right - f.left) + "\" height=\"" + num(f.bottom - f.top) + "\"/></clipPath></defs>\n";
  s += "<rect x=\"0\" y=\"0\" width=\"" + num(w) + "\" height=\"" + num(h) + "\" fill=\"#fff\"/>\n";
  s += axes_svg(f);
  s += "<g font-family=\"sans-serif\" fill=\"#222\">\n";
  s += "<text x=\"" + num((f.left + f.right) / 2) + "\" y=\"26\" font-size=\"15\" text-anchor=\"middle\">" +
       xml_escape(params.title) + "</text>\n";
  s += "<text x=\"" + num((f.left + f.right) / 2) + "\" y=\"" + num(h - 16) +
       "\" font-size=\"13\" text-anchor=\"middle\">" + xml_escape(params.x_label) + "</text>\n";
  std::string mid = num((f.top + f.bottom) / 2);
  s += "<text x=\"20\" y=\"" + mid + "\" font-size=\"13\" text-anchor=\"middle\" transform=\"rotate(-90 20 " + mid +
       ")\">" + xml_escape(params.y_label) + "</text>\n";
  s += "</g>\n";

  // Curves and the guide, clipped to the plot area.
  s += "<g clip-path=\"url(#plot-area)\">\n";
  bool guide = false;
  double gx = 0, gy = 0;
  if (params.guide_slope != 0 && !series.empty())
    for (size_t i = 0; i < std::min(series[0].x.size(), series[0].y.size()) && !guide; i++)
      if (plottable(series[0].x[i], series[0].y[i])) guide = true, gx = series[0].x[i], gy = series[0].y[i];
  if (guide) {
    // y = gy (x / gx)^slope is a straight line on log axes; draw it across the whole decade range of x.
    double ya = std::log10(gy) + params.guide_slope * (f.x0 - std::log10(gx));
    double yb = std::log10(gy) + params.guide_slope * (f.x1 - std::log10(gx));
    double pa = f.bottom - (ya - f.y0) / double(f.y1 - f.y0) * (f.bottom - f.top);
    double pb = f.bottom - (yb - f.y0) / double(f.y1 - f.y0) * (f.bottom - f.top);
    s += "<line x1=\"" + num(f.left) + "\" y1=\"" + num(pa) + "\" x2=\"" + num(f.right) + "\" y2=\"" + num(pb) +
         "\" stroke=\"#555\" stroke-width=\"1.5\" stroke-dasharray=\"7 5\"/>\n";
  }
  for (size_t k = 0; k < series.size(); k++) {
    const plot_series& sr = series[k];
    std::string color = plot_color(int(k)), d, marks;
    for (size_t i = 0; i < std::min(sr.x.size(), sr.y.size()); i++) {
      if (!plottable(sr.x[i], sr.y[i])) continue;
      std::string px = num(map_x(f, sr.x[i])), py = num(map_y(f, sr.y[i]));
      d += (d.empty() ? "M" : " L") + px + " " + py;
      marks += "<circle cx=\"" + px + "\" cy=\"" + py + "\" r=\"2.5\" fill=\"" + color + "\"/>\n";
    }
    if (d.empty()) continue;
    s += "<path d=\"" + d + "\" fill=\"none\" stroke=\"" + color +
         "\" stroke-width=\"2\" stroke-linejoin=\"round\" stroke-linecap=\"round\"><title>" + xml_escape(sr.label) +
         "</title></path>\n";
    s += marks;
  }
  s += "</g>\n";

  // Legend: a swatch and the label of every series, then the guide.
  s += "<g font-family=\"sans-serif\" font-size=\"13\" fill=\"#222\">\n";
  double lx = f.right + 18, ly = f.top + 12;
  for (size_t k = 0; k < series.size(); k++, ly += 22) {
    std::string color = plot_color(int(k));
    s += "<line x1=\"" + num(lx) + "\" y1=\"" + num(ly) + "\" x2=\"" + num(lx + 26) + "\" y2=\"" + num(ly) +
         "\" stroke=\"" + color + "\" stroke-width=\"2\"/>\n";
    s += "<circle cx=\"" + num(lx + 13) + "\" cy=\"" + num(ly) + "\" r=\"2.5\" fill=\"" + color + "\"/>\n";
    s += "<text x=\"" + num(lx + 34) + "\" y=\"" + num(ly + 4.5) + "\">" + xml_escape(series[k].label) + "</text>\n";
  }
  if (guide) {
    s += "<line x1=\"" + num(lx) + "\" y1=\"" + num(ly) + "\" x2=\"" + num(lx + 26) + "\" y2=\"" + num(ly) +
         "\" stroke=\"#555\" stroke-width=\"1.5\" stroke-dasharray=\"7 5\"/>\n";
    s += "<text x=\"" + num(lx + 34) + "\" y=\"" + num(ly + 4.5) + "\">" + xml_escape(params.guide_label) + "</text>\n";
  }
  s += "</g>\n</svg>\n";
  return s;
}

}  // namespace bl

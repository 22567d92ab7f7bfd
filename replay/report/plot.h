// Small scatter plots as PNG files (for `simgrass sweep`): log or linear axes with decade ticks
// and numbers, points coloured and shaped by category, an optional polyline (e.g. a Pareto
// front) and a legend. Pixels are drawn here; PNG encoding is stb_image_write's, glyphs are
// stb_easy_font's.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sg::plot {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

enum class Marker { Circle, Square, Triangle, Diamond };

struct Point {
  double x = 0, y = 0;  ///< data units (must be > 0 on a log axis, else the point is skipped)
  Rgb colour;
  Marker marker = Marker::Circle;
  bool hollow = false;       ///< drawn as an outline (a second category, e.g. LOD window)
  bool highlighted = false;  ///< ringed in black (e.g. on the Pareto front)
  std::string label;         ///< drawn next to the point when not empty and there is room
};

struct LegendEntry {
  std::string text;
  Rgb colour;
  Marker marker = Marker::Circle;
  bool hollow = false;
  bool isLine = false;  ///< a line sample (the polyline) instead of a marker
};

struct ScatterPlot {
  std::string title, xLabel, yLabel;
  bool logX = true, logY = true;
  int width = 1100, height = 760;  ///< whole image, px (the legend panel is on the right)
  std::vector<Point> points;
  std::vector<std::pair<double, double>> line;  ///< drawn in order, in data units
  Rgb lineColour{0, 0, 0};
  std::vector<LegendEntry> legend;
  std::vector<std::string> notes;  ///< extra lines under the legend
};

/// Where the data lands: the plot area in pixels and the data range it shows (log10 of the
/// data on a log axis). Log ranges are whole decades around the data.
struct Axes {
  int left = 0, top = 0, right = 0, bottom = 0;  ///< plot area, px (right/bottom exclusive)
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;         ///< shown range (log10 units on log axes)
  bool logX = true, logY = true;
  /// Pixel column / row of a data value (y grows downwards); NaN for values a log axis cannot show.
  double pixelX(double x) const;
  double pixelY(double y) const;
};

/// The axes render() uses for this plot.
Axes layoutAxes(const ScatterPlot& plot);

/// An 8-bit RGB image, rows top to bottom.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  Rgb at(int x, int y) const;
};

/// An image being drawn: clipped pixels, rectangles, thick lines and stb_easy_font text (the
/// plots here and the `simgrass diff` heat map).
struct Canvas {
  Image img;
  Canvas(int w, int h, Rgb background = {255, 255, 255});
  void set(int x, int y, Rgb c);
  /// Fills [x0, x1) x [y0, y1), clipped to the image.
  void fill(int x0, int y0, int x1, int y1, Rgb c);
  /// A line `thick` px wide from (x0, y0) to (x1, y1), clipped to [cx0, cx1) x [cy0, cy1).
  void line(double x0, double y0, double x1, double y1, int thick, Rgb c, int cx0, int cy0, int cx1, int cy1);
  /// ASCII text with its top-left corner at (x, y), glyphs scaled by `scale` (7 * scale px tall).
  void text(int x, int y, const std::string& s, int scale, Rgb c);
  static int textWidth(const std::string& s, int scale);
};

Image render(const ScatterPlot& plot);

/// The image as PNG bytes (empty when it cannot be encoded).
std::vector<uint8_t> encodePng(const Image& image);
/// Writes a PNG with writeFileAtomic (complete or absent); false with `error` set ("path: cannot
/// write (No space left on device)") when it cannot.
bool writePng(const std::string& path, const Image& image, std::string* error);

/// A short number for tick labels: "1e-3", "0.01", "100", "1e5".
std::string tickLabel(double value);

}  // namespace sg::plot

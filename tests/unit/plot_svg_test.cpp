// Unit tests of the runtime's SVG pictures with series (runtime/src/plot_svg.c):
// the document is well-formed XML; each named series has its own colour and
// a legend row in the order of its first mark; an equal-aspect frame has
// the data's proportions; the dots' path, decoded here, holds exactly the
// points inside the frame; and 10,000 points stay under 200 KB.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "sicm/runtime.h"
#include "test_files.hpp"

namespace {

using sicm_test::slurp;

std::string temp_dir() {
  return sicm_test::make_temp_dir("plot-svg");
}

// One element of the document: its name and attributes.
struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text; // the character data right after its start tag
};

// Parse the document the runtime writes (elements, attributes in double
// quotes, text, one <?xml ...?> declaration; no comments, CDATA or DTD):
// every start tag is closed in order and every attribute is quoted, else
// the error is set. Returns the elements in document order.
std::vector<Element> parse_xml(const std::string &doc, std::string &error) {
  std::vector<Element> elements;
  std::vector<std::string> open;
  size_t at = 0;
  if (doc.rfind("<?xml", 0) == 0) at = doc.find("?>") + 2;
  while ((at = doc.find('<', at)) != std::string::npos) {
    size_t end = doc.find('>', at);
    if (end == std::string::npos) return error = "unterminated tag", elements;
    std::string tag = doc.substr(at + 1, end - at - 1);
    at = end + 1;
    if (!tag.empty() && tag[0] == '/') {
      if (open.empty() || open.back() != tag.substr(1))
        return error = "mismatched </" + tag.substr(1) + ">", elements;
      open.pop_back();
      continue;
    }
    bool empty = !tag.empty() && tag.back() == '/';
    if (empty) tag.pop_back();
    Element e;
    size_t i = tag.find_first_of(" \n");
    e.name = tag.substr(0, i);
    while (i != std::string::npos && i < tag.size()) {
      i = tag.find_first_not_of(" \n", i);
      if (i == std::string::npos) break;
      size_t eq = tag.find('=', i);
      if (eq == std::string::npos || eq + 1 >= tag.size() || tag[eq + 1] != '"')
        return error = "unquoted attribute in <" + e.name + ">", elements;
      size_t close = tag.find('"', eq + 2);
      if (close == std::string::npos) return error = "unterminated attribute", elements;
      std::string value = tag.substr(eq + 2, close - eq - 2);
      if (value.find('<') != std::string::npos) return error = "< in an attribute", elements;
      e.attributes[tag.substr(i, eq - i)] = value;
      i = close + 1;
    }
    size_t next = doc.find('<', at);
    e.text = doc.substr(at, next == std::string::npos ? 0 : next - at);
    elements.push_back(e);
    if (!empty) open.push_back(e.name);
  }
  if (!open.empty()) error = "<" + open.back() + "> is not closed";
  return elements;
}

std::vector<Element> parse_file(const std::string &path) {
  std::string error;
  std::vector<Element> elements = parse_xml(slurp(path), error);
  EXPECT_EQ(error, "") << path;
  return elements;
}

// The absolute positions, in tenths of a pixel, of the dots a path draws
// with M/m moves each followed by h0 (and the ends of its l segments).
struct Decoded {
  std::vector<std::pair<long, long>> dots, line_ends;
};

Decoded decode_path(const std::string &d) {
  Decoded out;
  double x = 0, y = 0;
  char command = 0;
  size_t i = 0;
  auto number = [&]() {
    char *end;
    double v = std::strtod(d.c_str() + i, &end);
    EXPECT_NE(end, d.c_str() + i) << "a number at " << i << " of " << d.substr(0, 80);
    i = end - d.c_str();
    return v;
  };
  auto tenths = [](double v) { return std::lround(v * 10); };
  while (i < d.size()) {
    if (d[i] == ' ') {
      ++i;
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(d[i]))) command = d[i++];
    switch (command) {
    case 'M':
      x = number(), y = number();
      command = 'L'; // implicit repeats of a move are line-tos
      break;
    case 'm':
      x += number(), y += number();
      command = 'l';
      break;
    case 'l':
      x += number(), y += number();
      out.line_ends.push_back({tenths(x), tenths(y)});
      break;
    case 'L':
      x = number(), y = number();
      out.line_ends.push_back({tenths(x), tenths(y)});
      break;
    case 'h':
      EXPECT_EQ(number(), 0.0);
      out.dots.push_back({tenths(x), tenths(y)});
      break;
    default: ADD_FAILURE() << "unexpected command " << command; return out;
    }
  }
  return out;
}

double attr(const Element &e, const char *name) {
  auto it = e.attributes.find(name);
  EXPECT_NE(it, e.attributes.end()) << name << " of <" << e.name << ">";
  return it == e.attributes.end() ? NAN : std::atof(it->second.c_str());
}

// The frame's rectangle: the first <rect> with a black stroke.
const Element *frame_rect(const std::vector<Element> &elements) {
  for (const Element &e : elements)
    if (e.name == "rect" && e.attributes.count("stroke") && e.attributes.at("stroke") == "black")
      return &e;
  return nullptr;
}

std::vector<const Element *> paths(const std::vector<Element> &elements) {
  std::vector<const Element *> out;
  for (const Element &e : elements)
    if (e.name == "path") out.push_back(&e);
  return out;
}

} // namespace

// Three named series: three colours, all different, a legend row each in
// the order of their first marks, and the names in the TSV.
TEST(PlotSvg, SeriesHaveTheirOwnColoursAndALegend) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "s", "series", -1, 1, -1, 1);
  ASSERT_NE(p, nullptr);
  for (int i = 0; i < 50; ++i) {
    double t = i * 0.1;
    ASSERT_EQ(sicm_plot_series_point(p, "E = 1/8", 0.5 * std::cos(t), 0.5 * std::sin(t)), 0);
    ASSERT_EQ(sicm_plot_series_point(p, "chaotic <sea>", 0.8 * std::cos(t), 0.3 * std::sin(t)), 0);
    ASSERT_EQ(sicm_plot_series_line(p, "E = 1/12", 0, 0, 0.2 * std::cos(t), 0.2 * std::sin(t)), 0);
  }
  ASSERT_EQ(sicm_plot_style_series(p, "unused", 3, 0), 0); // no mark: no legend row
  sicm_plot_free(p);
  std::vector<Element> svg = parse_file(dir + "/s.svg");
  std::set<std::string> colours;
  for (const Element *e : paths(svg))
    colours.insert(e->attributes.at("stroke"));
  EXPECT_EQ(colours.size(), 3u);
  std::vector<std::string> legend;
  bool in_legend = false;
  for (const Element &e : svg) {
    if (e.name == "g" && e.attributes.count("class")) in_legend = true;
    if (in_legend && e.name == "text") legend.push_back(e.text);
  }
  std::vector<std::string> want = {"E = 1/8", "chaotic &lt;sea&gt;", "E = 1/12"};
  EXPECT_EQ(legend, want);
  std::string tsv = slurp(dir + "/s.tsv");
  EXPECT_NE(tsv.find("\tE = 1/8\n"), std::string::npos);
  EXPECT_NE(tsv.find("\tchaotic <sea>\n"), std::string::npos);
}

// Without named series there is no legend, and the unnamed series keeps
// one colour for points and one for segments.
TEST(PlotSvg, UnnamedMarksHaveNoLegend) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "u", nullptr, 0, 1, 0, 1);
  ASSERT_NE(p, nullptr);
  sicm_plot_point(p, 0.5, 0.5);
  sicm_plot_line(p, 0, 0, 1, 1);
  sicm_plot_free(p);
  std::string text = slurp(dir + "/u.svg");
  EXPECT_EQ(text.find("legend"), std::string::npos);
  std::vector<Element> svg = parse_file(dir + "/u.svg");
  ASSERT_EQ(paths(svg).size(), 2u);
  EXPECT_NE(paths(svg)[0]->attributes.at("stroke"), paths(svg)[1]->attributes.at("stroke"));
}

// An equal-aspect frame has the data's width-to-height ratio and stays
// inside the default one, centred; the default frame does not.
TEST(PlotSvg, EqualAspectKeepsTheDataProportions) {
  std::string dir = temp_dir();
  const double spans[][2] = {{4, 1}, {1, 4}, {6.4, 6.4}};
  for (const auto &span : spans) {
    for (int equal = 0; equal < 2; ++equal) {
      sicm_plot *p = sicm_plot_open(dir.c_str(), "a", nullptr, 0, span[0], 0, span[1]);
      ASSERT_NE(p, nullptr);
      sicm_plot_set_equal_aspect(p, equal);
      sicm_plot_free(p);
      std::vector<Element> svg = parse_file(dir + "/a.svg");
      const Element *rect = frame_rect(svg);
      ASSERT_NE(rect, nullptr);
      double ratio = attr(*rect, "width") / attr(*rect, "height");
      if (equal) {
        EXPECT_NEAR(ratio, span[0] / span[1], 1e-3) << span[0] << " x " << span[1];
      } else {
        EXPECT_GT(std::fabs(ratio - span[0] / span[1]), 0.1);
      }
      EXPECT_LE(attr(*rect, "x") + attr(*rect, "width"), 660);
      EXPECT_LE(attr(*rect, "y") + attr(*rect, "height"), 480);
    }
  }
}

// 10,000 points scattered over the frame (and 500 outside it): the file
// stays under 200 KB, and the dots' path, decoded, is exactly the set of
// the points inside, each where the frame's rectangle puts it, to a tenth
// of a pixel.
TEST(PlotSvg, TenThousandPointsAreSmallAndExact) {
  std::string dir = temp_dir();
  const double xmin = -3.2, xmax = 3.2, ymin = -2, ymax = 2;
  sicm_plot *p = sicm_plot_open(dir.c_str(), "big", "section", xmin, xmax, ymin, ymax);
  ASSERT_NE(p, nullptr);
  std::vector<std::pair<double, double>> points;
  unsigned long state = 12345;
  auto uniform = [&]() {
    state = state * 6364136223846793005ul + 1442695040888963407ul;
    return (state >> 11) * (1.0 / 9007199254740992.0);
  };
  for (int i = 0; i < 10500; ++i) {
    double x = xmin + (xmax - xmin) * uniform(), y = ymin + (ymax - ymin) * uniform();
    if (i % 21 == 0) y += 10; // outside: in the TSV, not drawn
    points.push_back({x, y});
    ASSERT_EQ(sicm_plot_series_point(p, "orbit", x, y), 0);
  }
  sicm_plot_free(p);
  std::string text = slurp(dir + "/big.svg");
  EXPECT_LT(text.size(), 200u * 1000u);
  std::vector<Element> svg = parse_file(dir + "/big.svg");
  const Element *rect = frame_rect(svg);
  ASSERT_NE(rect, nullptr);
  const double left = attr(*rect, "x"), top = attr(*rect, "y"), w = attr(*rect, "width"),
               h = attr(*rect, "height");
  std::set<std::pair<long, long>> want;
  for (auto [x, y] : points) {
    if (y > ymax) continue;
    double px = left + (x - xmin) / (xmax - xmin) * w, py = top + (ymax - y) / (ymax - ymin) * h;
    want.insert({std::lround(px * 10), std::lround(py * 10)});
  }
  ASSERT_EQ(paths(svg).size(), 1u);
  Decoded d = decode_path(paths(svg)[0]->attributes.at("d"));
  std::set<std::pair<long, long>> got(d.dots.begin(), d.dots.end());
  EXPECT_EQ(got.size(), d.dots.size()); // each dot once
  EXPECT_EQ(got, want);
  EXPECT_GE(want.size(), 9900u);
}

// A connected series is one polyline through its points in order, drawn
// without dots unless asked; a marker size is the dots' stroke width.
TEST(PlotSvg, ConnectedSeriesAndMarkerSizes) {
  std::string dir = temp_dir();
  sicm_plot *p = sicm_plot_open(dir.c_str(), "c", nullptr, 0, 10, 0, 10);
  ASSERT_NE(p, nullptr);
  ASSERT_EQ(sicm_plot_style_series(p, "line", -1, 1), 0);
  ASSERT_EQ(sicm_plot_style_series(p, "big dots", 7, 0), 0);
  for (int i = 0; i <= 10; ++i) {
    sicm_plot_series_point(p, "line", i, i % 3);
    sicm_plot_series_point(p, "big dots", i, 5 + i % 2);
  }
  sicm_plot_free(p);
  std::vector<Element> svg = parse_file(dir + "/c.svg");
  std::vector<const Element *> ps = paths(svg);
  ASSERT_EQ(ps.size(), 2u);
  Decoded line = decode_path(ps[0]->attributes.at("d"));
  EXPECT_EQ(line.dots.size(), 0u);
  EXPECT_EQ(line.line_ends.size(), 10u); // 11 points, 10 pieces
  EXPECT_EQ(ps[1]->attributes.at("stroke-width"), "7");
  EXPECT_EQ(decode_path(ps[1]->attributes.at("d")).dots.size(), 11u);
}

// Sparse plots get larger dots by default, dense ones smaller; a frame's
// marker size overrides both.
TEST(PlotSvg, DefaultDotsShrinkAsPointsGrow) {
  std::string dir = temp_dir();
  const int counts[] = {100, 1000, 5000};
  double previous = 1e9;
  for (int n : counts) {
    sicm_plot *p = sicm_plot_open(dir.c_str(), "d", nullptr, 0, 1, 0, 1);
    for (int i = 0; i < n; ++i)
      sicm_plot_point(p, (i + 0.5) / n, 0.5);
    sicm_plot_free(p);
    std::vector<Element> svg = parse_file(dir + "/d.svg");
    double width = attr(*paths(svg)[0], "stroke-width");
    EXPECT_LT(width, previous) << n << " points";
    EXPECT_GE(width, 2);
    previous = width;
  }
  sicm_plot *p = sicm_plot_open(dir.c_str(), "d", nullptr, 0, 1, 0, 1);
  sicm_plot_set_marker_size(p, 1.5);
  sicm_plot_point(p, 0.5, 0.5);
  sicm_plot_free(p);
  EXPECT_EQ(paths(parse_file(dir + "/d.svg"))[0]->attributes.at("stroke-width"), "1.5");
}

// The legend goes in the corner asked for, inside the frame, or nowhere.
TEST(PlotSvg, LegendPlacement) {
  std::string dir = temp_dir();
  const sicm_plot_legend places[] = {SICM_PLOT_LEGEND_TOP_LEFT, SICM_PLOT_LEGEND_BOTTOM_RIGHT,
                                     SICM_PLOT_LEGEND_NONE};
  for (sicm_plot_legend where : places) {
    sicm_plot *p = sicm_plot_open(dir.c_str(), "l", nullptr, 0, 1, 0, 1);
    ASSERT_EQ(sicm_plot_set_legend(p, where), 0);
    sicm_plot_series_point(p, "a", 0.5, 0.5);
    sicm_plot_free(p);
    std::vector<Element> svg = parse_file(dir + "/l.svg");
    const Element *frame = frame_rect(svg);
    const Element *box = nullptr;
    for (const Element &e : svg)
      if (e.name == "rect" && e.attributes.count("fill-opacity")) box = &e;
    if (where == SICM_PLOT_LEGEND_NONE) {
      EXPECT_EQ(box, nullptr);
      continue;
    }
    ASSERT_NE(box, nullptr);
    const double fx = attr(*frame, "x"), fy = attr(*frame, "y");
    const double fw = attr(*frame, "width"), fh = attr(*frame, "height");
    const double bx = attr(*box, "x"), by = attr(*box, "y");
    EXPECT_GE(bx, fx);
    EXPECT_LE(bx + attr(*box, "width"), fx + fw);
    const bool left = bx < fx + fw / 2, high = by < fy + fh / 2;
    EXPECT_EQ(left, where == SICM_PLOT_LEGEND_TOP_LEFT);
    EXPECT_EQ(high, where == SICM_PLOT_LEGEND_TOP_LEFT);
  }
  sicm_plot *p = sicm_plot_open(dir.c_str(), "l", nullptr, 0, 1, 0, 1);
  EXPECT_EQ(sicm_plot_set_legend(p, static_cast<sicm_plot_legend>(17)), -1);
  sicm_plot_free(p);
}

// By default the legend takes the corner where it hides the fewest marks.
TEST(PlotSvg, LegendAvoidsTheMarks) {
  std::string dir = temp_dir();
  // Marks crowd every corner but the bottom left, whatever the legend's size.
  sicm_plot *p = sicm_plot_open(dir.c_str(), "b", nullptr, 0, 1, 0, 1);
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 100; ++j)
      if (i > 30 || j > 30)
        sicm_plot_series_point(p, (i + j) % 2 ? "odd" : "even", i / 100.0, j / 100.0);
  sicm_plot_free(p);
  std::vector<Element> svg = parse_file(dir + "/b.svg");
  const Element *frame = frame_rect(svg);
  const Element *box = nullptr;
  for (const Element &e : svg)
    if (e.name == "rect" && e.attributes.count("fill-opacity")) box = &e;
  ASSERT_NE(box, nullptr);
  EXPECT_LT(attr(*box, "x"), attr(*frame, "x") + attr(*frame, "width") / 2);  // left
  EXPECT_GT(attr(*box, "y"), attr(*frame, "y") + attr(*frame, "height") / 2); // bottom
}

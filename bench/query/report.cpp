#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "tightbvh/build.hpp"
#include "view/decimate.hpp"

namespace tightbvh::bench {
namespace {

std::string esc(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

std::string fmt(double v, const char* f = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

const char* kColors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                         "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

// Horizontal bars of queries/s (log scale), one chart per scenario and mode.
std::string qps_chart(const std::vector<const Row*>& rows, const std::string& title) {
  const double width = 900, left = 170, bar = 18, gap = 6, top = 30;
  const double height = top + rows.size() * (bar + gap) + 30;
  double lo = 1e300, hi = 0;
  for (const Row* r : rows)
    if (r->qps() > 0) lo = std::min(lo, r->qps()), hi = std::max(hi, r->qps());
  if (hi <= 0) return {};
  const double l0 = std::floor(std::log10(lo) - 0.3), l1 = std::ceil(std::log10(hi));
  const auto x = [&](double q) { return left + (width - left - 90) * (std::log10(q) - l0) / std::max(l1 - l0, 1.0); };
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
    << "' font-family='sans-serif' font-size='12'>";
  s << "<text x='4' y='16' font-weight='bold'>" << esc(title) << " (queries/s, log scale)</text>";
  for (double e = l0; e <= l1; e += 1) {
    s << "<line x1='" << x(std::pow(10, e)) << "' y1='" << top - 4 << "' x2='" << x(std::pow(10, e)) << "' y2='"
      << height - 24 << "' stroke='#ddd'/>";
    s << "<text x='" << x(std::pow(10, e)) << "' y='" << height - 10 << "' text-anchor='middle'>1e" << int(e)
      << "</text>";
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = *rows[i];
    const double y = top + i * (bar + gap);
    const bool ours = r.engine.rfind("tightbvh-", 0) == 0;
    const std::string color = ours ? "#2ca02c" : (r.engine.rfind("fcl-export", 0) == 0 ? "#98df8a" : "#1f77b4");
    s << "<text x='" << left - 6 << "' y='" << y + 13 << "' text-anchor='end'>" << esc(r.engine) << "</text>";
    if (r.qps() > 0)
      s << "<rect x='" << left << "' y='" << y << "' width='" << std::max(1.0, x(r.qps()) - left) << "' height='"
        << bar << "' fill='" << color << "'/>"
        << "<text x='" << x(r.qps()) + 4 << "' y='" << y + 13 << "'>" << fmt(r.qps(), "%.0f")
        << (r.agreement.mismatches() ? " (mismatches)" : "") << "</text>";
  }
  s << "</svg>";
  return s.str();
}

struct Level {
  double volume = 0;
  int nodes = 0;
};

std::vector<Level> volume_per_level(const Tree& tree) {
  std::vector<Level> levels;
  std::vector<std::pair<std::uint32_t, int>> stack{{0u, 0}};
  while (!stack.empty()) {
    const auto [i, d] = stack.back();
    stack.pop_back();
    if (int(levels.size()) <= d) levels.resize(d + 1);
    levels[d].volume += tree.nodes[i].box.volume();
    ++levels[d].nodes;
    if (!tree.nodes[i].is_leaf()) {
      stack.push_back({tree.nodes[i].first, d + 1});
      stack.push_back({tree.nodes[i].first + 1, d + 1});
    }
  }
  return levels;
}

std::string volume_chart(const std::vector<std::pair<std::string, std::vector<Level>>>& series) {
  const double width = 900, height = 360, left = 70, bottom = 40, top = 30, right = 150;
  double lo = 1e300, hi = 0;
  std::size_t depth = 0;
  for (const auto& [name, levels] : series) {
    depth = std::max(depth, levels.size());
    for (const Level& l : levels)
      if (l.volume > 0) lo = std::min(lo, l.volume), hi = std::max(hi, l.volume);
  }
  if (hi <= 0) return {};
  lo = std::max(lo, hi * 1e-6);  // the deepest levels hold flat single-triangle boxes (~0 volume)
  const double l0 = std::floor(std::log10(lo)), l1 = std::ceil(std::log10(hi));
  const auto x = [&](double level) { return left + (width - left - right) * level / std::max<double>(depth - 1, 1); };
  const auto y = [&](double v) { return top + (height - top - bottom) * (l1 - std::log10(v)) / std::max(l1 - l0, 1.0); };
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << width << "' height='" << height
    << "' font-family='sans-serif' font-size='12'>";
  s << "<text x='4' y='16' font-weight='bold'>sum of box volumes per tree level (mesh A, log scale)</text>";
  for (double e = l0; e <= l1; e += 1)
    s << "<line x1='" << left << "' y1='" << y(std::pow(10, e)) << "' x2='" << width - right << "' y2='"
      << y(std::pow(10, e)) << "' stroke='#ddd'/><text x='" << left - 6 << "' y='" << y(std::pow(10, e)) + 4
      << "' text-anchor='end'>1e" << int(e) << "</text>";
  for (std::size_t d = 0; d < depth; d += std::max<std::size_t>(1, depth / 10))
    s << "<text x='" << x(double(d)) << "' y='" << height - bottom + 16 << "' text-anchor='middle'>" << d << "</text>";
  s << "<text x='" << (left + width - right) / 2 << "' y='" << height - 6 << "' text-anchor='middle'>tree level</text>";
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& [name, levels] = series[k];
    s << "<polyline fill='none' stroke-width='2' stroke='" << kColors[k % 10] << "' points='";
    for (std::size_t d = 0; d < levels.size(); ++d)
      if (levels[d].volume >= lo) s << x(double(d)) << ',' << y(levels[d].volume) << ' ';
    s << "'/><text x='" << width - right + 10 << "' y='" << top + 16 * k + 10 << "' fill='" << kColors[k % 10]
      << "'>" << esc(name) << "</text>";
  }
  s << "</svg>";
  return s.str();
}

// Orthographic view along -z (x right, y up), fitted to the mesh's bounds.
struct View {
  double sx = 1, ox = 0, oy = 0, size = 420;
  [[nodiscard]] std::pair<double, double> operator()(const Vec3& p) const {
    return {(p.x() - ox) * sx + 10, size - 10 - (p.y() - oy) * sx};
  }
};

std::vector<std::pair<double, double>> hull2d(std::vector<std::pair<double, double>> p) {
  std::sort(p.begin(), p.end());
  std::vector<std::pair<double, double>> h(2 * p.size());
  const auto cross = [](auto o, auto a, auto b) {
    return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
  };
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k > 1 ? k - 1 : k);
  return h;
}

std::string boxes_picture(const Tree& tree, int level, const View& view, const std::string& title) {
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << view.size << "' height='" << view.size + 20
    << "' font-family='sans-serif' font-size='12'><text x='4' y='" << view.size + 14 << "'>" << esc(title)
    << "</text><use href='#mesh-a'/>";
  std::vector<std::pair<std::uint32_t, int>> stack{{0u, 0}};
  int k = 0;
  while (!stack.empty()) {
    const auto [i, d] = stack.back();
    stack.pop_back();
    const Node& n = tree.nodes[i];
    if (d == level || (n.is_leaf() && d < level)) {
      std::vector<std::pair<double, double>> pts;
      for (const Vec3& c : n.box.obb().corners()) pts.push_back(view(c));
      s << "<polygon fill='" << kColors[k % 10] << "' fill-opacity='0.12' stroke='" << kColors[k % 10]
        << "' stroke-width='1' points='";
      for (const auto& [x, y] : hull2d(pts)) s << fmt(x, "%.1f") << ',' << fmt(y, "%.1f") << ' ';
      s << "'/>";
      ++k;
      continue;
    }
    if (!n.is_leaf()) {
      stack.push_back({n.first, d + 1});
      stack.push_back({n.first + 1, d + 1});
    }
  }
  s << "</svg>";
  return s.str();
}

// A typical pose of a scenario: A (blue) at the identity, B (green) at the pose, the touching
// triangles (red) drawn over both. Orthographic view from the same direction as the view pages'
// initial one (apps/view/page.html), painter's algorithm over flat-shaded triangles; meshes above
// kMaxPictureTriangles are drawn decimated, the contacts always from the full meshes.
struct Projection {
  Vec3 x, y, z, center;
  double scale = 1, half = 200;
  [[nodiscard]] Vec3 operator()(const Vec3& p) const {
    const Vec3 q = p - center;
    return {half + scale * q.dot(x), half - scale * q.dot(y), q.dot(z)};
  }
};

std::string hex(int r, int g, int b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", std::clamp(r, 0, 255), std::clamp(g, 0, 255), std::clamp(b, 0, 255));
  return buf;
}

std::string pose_picture(const Input& input, const PosePicture& picture, const std::string& caption) {
  const double size = 420;
  const view::DrawnMesh drawn_a = view::decimate_for_drawing(input.a, kMaxPictureTriangles);
  const view::DrawnMesh drawn_b = view::decimate_for_drawing(input.b, kMaxPictureTriangles);
  Aabb bounds = bounds_of(input.a.vertices);
  for (const Vec3& v : input.b.vertices) bounds.extend(picture.pose.apply(v));
  Projection view;
  const double yaw = 0.6, pitch = 0.35;
  view.z = Vec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
  view.x = Vec3(view.z.z(), 0, -view.z.x()).normalized();
  view.y = view.z.cross(view.x);
  view.center = bounds.center();
  view.half = size / 2;
  view.scale = (size / 2 - 8) / std::max(0.5 * bounds.diagonal(), 1e-300);
  struct Face {
    std::array<Vec3, 3> p;  // projected (x, y in pixels, z depth: larger is nearer)
    int r, g, b;
  };
  std::vector<Face> faces;
  const auto add = [&](const Mesh& mesh, const Pose& pose, int r, int g, int b) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto c = mesh.corners(t);
      const Vec3 p0 = pose.apply(c[0]), p1 = pose.apply(c[1]), p2 = pose.apply(c[2]);
      const Vec3 n = (p1 - p0).cross(p2 - p0);
      const double light = 0.45 + 0.55 * (n.norm() > 0 ? std::abs(n.dot(view.z)) / n.norm() : 1.0);
      faces.push_back({{view(p0), view(p1), view(p2)}, int(r * light), int(g * light), int(b * light)});
    }
  };
  add(drawn_a.mesh, Pose{}, 127, 167, 217);
  add(drawn_b.mesh, picture.pose, 143, 207, 143);
  std::sort(faces.begin(), faces.end(), [](const Face& f, const Face& g) {
    return f.p[0].z() + f.p[1].z() + f.p[2].z() < g.p[0].z() + g.p[1].z() + g.p[2].z();
  });
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << size << "' height='" << size + 36
    << "' font-family='sans-serif' font-size='12'><rect width='100%' height='100%' fill='#fff'/>";
  const auto path = [&](const std::array<Vec3, 3>& p) {
    std::string d;
    for (int k = 0; k < 3; ++k) {
      d += k ? 'L' : 'M';
      d += fmt(p[k].x(), "%.1f");
      d += ' ';
      d += fmt(p[k].y(), "%.1f");
    }
    return d + 'Z';
  };
  for (const Face& f : faces) s << "<path fill='" << hex(f.r, f.g, f.b) << "' d='" << path(f.p) << "'/>";
  // Contacts over everything (also where hidden), with an outline so that small ones show.
  std::set<std::uint32_t> ta, tb;
  for (const auto& [a, b] : picture.pairs) ta.insert(a), tb.insert(b);
  s << "<g fill='#e0202a' stroke='#e0202a' stroke-width='1.2' stroke-linejoin='round'>";
  for (const std::uint32_t t : ta) {
    const auto c = input.a.corners(t);
    s << "<path d='" << path({view(c[0]), view(c[1]), view(c[2])}) << "'/>";
  }
  for (const std::uint32_t t : tb) {
    const auto c = input.b.corners(t);
    s << "<path d='" << path({view(picture.pose.apply(c[0])), view(picture.pose.apply(c[1])),
                              view(picture.pose.apply(c[2]))})
      << "'/>";
  }
  s << "</g><text x='4' y='" << size + 14 << "' font-weight='bold'>" << esc(caption) << "</text><text x='4' y='"
    << size + 30 << "'>" << picture.pairs.size() << " touching triangle pairs (" << ta.size() << " of A, " << tb.size()
    << " of B)</text></svg>";
  return s.str();
}

}  // namespace

void write_report(const std::filesystem::path& dir, const RunInfo& info, const std::vector<Row>& rows,
                  const Input& input, const std::vector<PosePicture>& pictures) {
  std::filesystem::create_directories(dir);
  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset='utf-8'><title>tightbvh-bench report</title><style>"
       "body{font-family:sans-serif;max-width:1200px;margin:16px}table{border-collapse:collapse;font-size:12px}"
       "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}td:first-child{text-align:left}"
       ".pics svg{margin:4px;border:1px solid #eee}</style></head><body>";
  h << "<h1>tightbvh-bench</h1><p>A = " << esc(info.mesh_a) << " (" << info.triangles_a << " triangles), B = "
    << esc(info.mesh_b) << " (" << info.triangles_b << " triangles), " << info.poses << " poses per scenario, seed "
    << info.seed << ".<br>Reference: " << esc(info.reference) << "</p>";

  // Plots of queries/s per scenario and mode.
  h << "<h2>Queries per second</h2>";
  std::vector<std::string> scenarios;
  for (const Row& r : rows)
    if (std::find(scenarios.begin(), scenarios.end(), r.scenario) == scenarios.end()) scenarios.push_back(r.scenario);
  for (const auto& sc : scenarios)
    for (Mode m : {Mode::first_hit, Mode::all_pairs, Mode::distance, Mode::margin, Mode::solid}) {
      std::vector<const Row*> sel;
      for (const Row& r : rows)
        if (r.scenario == sc && r.mode == m && r.engine != "reference") sel.push_back(&r);
      if (!sel.empty()) h << "<div>" << qps_chart(sel, sc + " / " + to_string(m)) << "</div>";
    }

  // One typical pose per scenario, with its contacts.
  if (!pictures.empty()) {
    const auto drawn_note = [](const Mesh& m) {
      return m.triangles.size() > kMaxPictureTriangles
                 ? std::to_string(m.triangles.size()) + " triangles, drawn decimated to at most " +
                       std::to_string(kMaxPictureTriangles) + " (vertex clustering)"
                 : std::to_string(m.triangles.size()) + " triangles, all drawn";
    };
    h << "<h2>A typical pose per scenario</h2><p>A (blue) at the identity, B (green) at the pose; the touching "
         "triangles (the reference's pairs) in red, drawn over both meshes even where hidden. Per scenario the pose "
         "with the median number of touching pairs among the touching poses. Meshes above "
      << kMaxPictureTriangles << " triangles are drawn simplified (what is drawn, not what is measured): A "
      << esc(drawn_note(input.a)) << "; B " << esc(drawn_note(input.b)) << ".</p><div class='pics'>";
    for (const PosePicture& picture : pictures) {
      const std::string svg = pose_picture(input, picture,
                                           picture.scenario + ": pose " + std::to_string(picture.index + 1) + " of " +
                                               std::to_string(picture.poses));
      h << svg;
      std::ofstream file(dir / ("pose-" + picture.scenario + ".svg"));
      file << "<?xml version='1.0' encoding='utf-8'?>\n" << svg << '\n';
      if (!file) throw InputError((dir / ("pose-" + picture.scenario + ".svg")).string() + ": write failed");
    }
    h << "</div><p>";
    for (const PosePicture& picture : pictures)
      h << esc(picture.scenario) << ": pose " << picture.index + 1 << ", " << esc(picture.why) << ". ";
    h << "</p>";
  }

  // The table.
  h << "<h2>Results</h2><table><tr><th>scenario</th><th>engine</th><th>mode</th><th>build s</th><th>queries/s</th>"
       "<th>vs fcl-obb (distance: fcl-obbrss)</th><th>hits</th><th>pairs</th><th>agreement</th></tr>";
  for (const Row& r : rows) {
    if (r.engine == "reference") continue;
    h << "<tr><td>" << esc(r.scenario) << "</td><td>" << esc(r.engine) << "</td><td>" << to_string(r.mode)
      << "</td><td>" << fmt(r.build_seconds, "%.3f") << "</td><td>" << fmt(r.qps(), "%.1f") << "</td><td>"
      << (r.ratio ? fmt(*r.ratio, "%.2fx") : "-") << "</td><td>" << r.hits << "</td><td>"
      << (reports_pairs(r.mode) ? std::to_string(r.pairs) : "-") << "</td><td style='text-align:left'>"
      << esc(agreement_text(r)) << "</td></tr>";
  }
  h << "</table>";
  if (!info.notes.empty()) {
    h << "<ul>";
    for (const auto& n : info.notes) h << "<li>" << esc(n) << "</li>";
    h << "</ul>";
  }

  // Trees of mesh A per fitter: volume per level, and boxes of a few levels over the mesh.
  std::vector<std::pair<std::string, Tree>> trees;
  for (const Fitter& f : std::vector<Fitter>{FitMethod::aabb, FitMethod::pca, FitMethod::approx, AutoFit{}}) {
    BuildOptions o;
    o.fitter = f;
    try {
      trees.emplace_back(to_string(f), build(input.a, o));
    } catch (const std::exception& e) {
      h << "<p>fitter " << esc(to_string(f)) << ": " << esc(e.what()) << "</p>";
    }
  }
  std::vector<std::pair<std::string, std::vector<Level>>> series;
  for (const auto& [name, tree] : trees) series.emplace_back(name, volume_per_level(tree));
  h << "<h2>Box volume per tree level</h2>" << volume_chart(series);
  h << "<table><tr><th>fitter</th>";
  std::size_t depth = 0;
  for (const auto& [n, l] : series) depth = std::max(depth, l.size());
  for (std::size_t d = 0; d < std::min<std::size_t>(depth, 12); ++d) h << "<th>level " << d << "</th>";
  h << "</tr>";
  for (const auto& [name, levels] : series) {
    h << "<tr><td>" << esc(name) << "</td>";
    for (std::size_t d = 0; d < std::min<std::size_t>(depth, 12); ++d)
      h << "<td>" << (d < levels.size() ? fmt(levels[d].volume) : "") << "</td>";
    h << "</tr>";
  }
  h << "</table>";

  const Aabb bounds = bounds_of(input.a.vertices);
  View view;
  // Padded by a quarter of the size: rotated boxes reach beyond the mesh's bounds.
  const double span = 1.5 * std::max(bounds.extents().x(), bounds.extents().y());
  view.ox = bounds.center().x() - 0.5 * span;
  view.oy = bounds.center().y() - 0.5 * span;
  view.sx = (view.size - 20) / span;
  std::ostringstream mesh;  // drawn once, referenced by every picture
  mesh << "<svg width='0' height='0' style='position:absolute'><defs><path id='mesh-a' fill='#bbb' "
          "fill-opacity='0.35' stroke='#999' stroke-width='0.2' d='";
  for (std::size_t t = 0; t < input.a.triangles.size(); ++t) {
    const auto c = input.a.corners(t);
    for (int k = 0; k < 3; ++k) {
      const auto [x, y] = view(c[k]);
      mesh << (k ? 'L' : 'M') << fmt(x, "%.1f") << ' ' << fmt(y, "%.1f");
    }
    mesh << 'Z';
  }
  mesh << "'/></defs></svg>";
  h << "<h2>Boxes over mesh A (orthographic view along z)</h2>" << mesh.str() << "<div class='pics'>";
  for (const auto& [name, tree] : trees)
    for (int level : {2, 5, 8})
      h << boxes_picture(tree, level, view, name + ", level " + std::to_string(level));
  h << "</div></body></html>\n";
  std::ofstream out(dir / "index.html");
  out << h.str();
  if (!out) throw InputError((dir / "index.html").string() + ": write failed");
}

}  // namespace tightbvh::bench

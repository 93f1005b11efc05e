// tightbvh points MESH POINTS [--signed] [--max-distance D] [--threads N] [--json] [-o OUT]: the closest
// point on MESH of each point of POINTS (text, one "x y z" a line, or a .npy array of shape (N, 3),
// float64 or float32), or with --signed the signed distance (negative inside; a closed mesh).
// Text output: one line per point, "distance x y z triangle" (the closest point, the triangle's index).
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "tightbvh/error.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/point_query.hpp"

namespace tightbvh::cli {
namespace {

struct Args {
  std::string mesh, points, out;
  bool signed_distance = false;
  double max_distance = std::numeric_limits<double>::infinity();
  unsigned threads = 0;
  bool json = false;
};

[[nodiscard]] bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Text: one point a line, three numbers separated by blanks; empty lines and lines starting with
// '#' are skipped. A bad line is named by its number.
[[nodiscard]] std::vector<Vec3> read_text_points(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the points file");
  std::vector<Vec3> points;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    Vec3 p;
    std::string extra;
    if (!(fields >> p.x() >> p.y() >> p.z()) || (fields >> extra))
      throw InputError(path + ":" + std::to_string(number) + ": expected three numbers \"x y z\", got '" + line + "'");
    if (!p.allFinite()) throw InputError(path + ":" + std::to_string(number) + ": not finite: '" + line + "'");
    points.push_back(p);
  }
  return points;
}

// The value of `key` in a .npy header dictionary ("{'descr': '<f8', 'fortran_order': False,
// 'shape': (3, 3), }"), up to the next top-level comma; "" when absent.
[[nodiscard]] std::string npy_field(const std::string& header, const std::string& key) {
  const std::size_t at = header.find("'" + key + "':");
  if (at == std::string::npos) return "";
  const std::size_t start = header.find_first_not_of(' ', at + key.size() + 3);
  if (start == std::string::npos) return "";
  const std::size_t end = header[start] == '(' ? header.find(')', start) : header.find(',', start);
  if (end == std::string::npos) return "";
  if (header[start] == '(') return header.substr(start, end + 1 - start);
  return header.substr(start, end - start);
}

// A NumPy .npy file (format versions 1 to 3): a little-endian float64 or float32 array of shape
// (N, 3), C or Fortran order; anything else is an InputError saying what was found.
[[nodiscard]] std::vector<Vec3> read_npy_points(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the points file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto fail = [&](const std::string& why) { throw InputError(path + ": not a (N, 3) float .npy array: " + why); };
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) fail("no .npy magic string");
  const auto major = static_cast<unsigned char>(bytes[6]);
  if (major < 1 || major > 3) fail("format version " + std::to_string(major));
  const std::size_t size_bytes = major == 1 ? 2 : 4;
  std::size_t header_size = 0;
  for (std::size_t k = 0; k < size_bytes; ++k)
    header_size |= std::size_t{static_cast<unsigned char>(bytes[8 + k])} << (8 * k);
  const std::size_t data_start = 8 + size_bytes + header_size;
  if (data_start > bytes.size()) fail("the header runs past the end of the file");
  const std::string header = bytes.substr(8 + size_bytes, header_size);
  const std::string descr = npy_field(header, "descr"), order = npy_field(header, "fortran_order"),
                    shape = npy_field(header, "shape");
  std::size_t item = 0;
  if (descr == "'<f8'") item = 8;
  else if (descr == "'<f4'") item = 4;
  else fail("dtype " + (descr.empty() ? std::string("missing") : descr) + " (expected '<f8' or '<f4')");
  if (order != "True" && order != "False") fail("fortran_order '" + order + "'");
  std::size_t rows = 0, columns = 0;
  char close = 0;
  std::istringstream dims(shape);
  char open = 0, comma = 0;
  if (!(dims >> open >> rows >> comma >> columns >> close) || open != '(' || comma != ',' || close != ')' ||
      columns != 3)
    fail("shape " + (shape.empty() ? std::string("missing") : shape));
  if (bytes.size() - data_start != rows * 3 * item)
    fail(std::to_string(bytes.size() - data_start) + " data bytes for shape " + shape);
  const char* data = bytes.data() + data_start;
  std::vector<Vec3> points(rows);
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t index = order == "True" ? k * rows + i : i * 3 + k;
      if (item == 8) {
        double x;
        std::memcpy(&x, data + 8 * index, 8);
        points[i][static_cast<int>(k)] = x;
      } else {
        float x;
        std::memcpy(&x, data + 4 * index, 4);
        points[i][static_cast<int>(k)] = x;
      }
    }
  for (std::size_t i = 0; i < rows; ++i)
    if (!points[i].allFinite()) throw InputError(path + ": row " + std::to_string(i) + " is not finite");
  return points;
}

[[nodiscard]] std::vector<Vec3> read_points(const std::string& path) {
  return ends_with(path, ".npy") ? read_npy_points(path) : read_text_points(path);
}

[[nodiscard]] nlohmann::json to_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

void print(const Args& args, const std::vector<ClosestPoint>& results, double seconds, std::ostream& out) {
  if (args.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const ClosestPoint& r : results) {
      nlohmann::json item = {{"distance", r.distance}, {"beyond_max_distance", r.beyond_max_distance}};
      if (!r.beyond_max_distance) {
        item["point"] = to_json(r.point);
        item["triangle"] = r.triangle;
        item["barycentric"] = to_json(r.barycentric);
      }
      list.push_back(item);
    }
    const nlohmann::json doc = {{"mesh", args.mesh},       {"points", args.points}, {"signed", args.signed_distance},
                                {"count", results.size()}, {"seconds", seconds},    {"results", list}};
    out << doc.dump(2) << '\n';
    return;
  }
  out.precision(17);
  for (const ClosestPoint& r : results) {
    if (r.beyond_max_distance)
      out << (r.distance < 0.0 ? "<= " : ">= ") << r.distance << " beyond\n";
    else
      out << r.distance << ' ' << r.point.x() << ' ' << r.point.y() << ' ' << r.point.z() << ' ' << r.triangle << '\n';
  }
}

void run(const Args& args) {
  const std::vector<Vec3> points = read_points(args.points);
  BuildOptions build_options;
  build_options.threads = args.threads;
  const Model model(load_mesh(args.mesh), build_options);
  std::ofstream file;
  if (!args.out.empty()) {
    file.open(args.out);
    if (!file) throw InputError(args.out + ": cannot write the output file");
  }
  const PointQueryOptions options{args.max_distance, args.threads};
  const auto start = std::chrono::steady_clock::now();
  const std::vector<ClosestPoint> results = args.signed_distance
                                                ? signed_distance(model, Pose::identity(), points, options)
                                                : closest_points(model, Pose::identity(), points, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  print(args, results, seconds, args.out.empty() ? std::cout : file);
  if (!args.out.empty() && !file) throw InputError(args.out + ": writing failed");
}

}  // namespace

void add_points_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("points", "closest points on a mesh, or signed distances, of many points");
  auto args = std::make_shared<Args>();
  cmd->add_option("mesh", args->mesh, "the mesh (OBJ, OFF, STL, PLY, ...)")->required();
  cmd->add_option("points", args->points,
                  "the points: text, one \"x y z\" a line ('#' comments), or a .npy array (N, 3) of float64 or "
                  "float32")
      ->required();
  cmd->add_flag("--signed", args->signed_distance,
                "signed distances: negative inside, 0 on the surface (exact sign; the mesh must be closed)");
  auto* max_distance = cmd->add_option("--max-distance", args->max_distance,
                                       "points with no triangle closer than this print 'beyond'")
                           ->capture_default_str();
  cmd->add_option("--threads", args->threads, "threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--json", args->json, "print JSON instead of text");
  cmd->add_option("-o,--output", args->out, "write the output to this file instead of standard output");
  cmd->footer(
      "Output: one line per point, \"distance x y z triangle\" (the closest point and its triangle).\n"
      "Example:\n  tightbvh points meshes/fandisk.off examples/points/probes.txt --signed");
  cmd->callback([args, max_distance] {
    require_non_negative(*max_distance, args->max_distance, true);
    run(*args);
  });
}

}  // namespace tightbvh::cli

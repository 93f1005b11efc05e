// Mesh loading through assimp: one well-kept reader for OBJ, OFF, STL and PLY, guarded by our
// own structural checks (format_checks.cpp) where assimp would abort, over-allocate or silently
// return a wrong mesh.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <limits>
#include <fstream>
#include <iterator>
#include <system_error>
#include <unordered_map>

#include "format_checks.hpp"
#include "tightbvh/mesh.hpp"

namespace tightbvh {
namespace {

std::string read_all(const std::filesystem::path& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name + ": cannot open file for reading");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(name + ": read error");
  return bytes;
}

io::Format detect_format(const std::filesystem::path& path, std::string_view bytes, const std::string& name) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".obj") return io::Format::obj;
  if (ext == ".off") return io::Format::off;
  if (ext == ".stl") return io::Format::stl;
  if (ext == ".ply") return io::Format::ply;
  if (!ext.empty())
    throw InputError(name + ": unknown format: extension '" + path.extension().string() +
                     "' is not one of .obj, .off, .stl, .ply");
  io::Format format{};
  if (!io::sniff_format(bytes, format))
    throw InputError(name + ": unknown format: no extension and the content is not OBJ, OFF, STL or PLY");
  return format;
}

// Exact welding (bitwise-equal coordinates, -0 == +0): undoes the per-corner vertex copies that
// assimp makes for OBJ and STL, so hulls and fits see each point once. Never moves a point.
struct PositionKey {
  std::array<std::uint64_t, 3> bits;
  bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::uint64_t b : k.bits) h = (h ^ b) * 1099511628211ull + (h >> 29);
    return static_cast<std::size_t>(h);
  }
};

// Phase 1: the path names a regular file.
void check_path(const std::filesystem::path& path, const std::string& name) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(name + ": no such file");
  if (std::filesystem::is_directory(status)) throw InputError(name + ": is a directory, not a mesh file");
  if (!std::filesystem::is_regular_file(status)) throw InputError(name + ": not a regular file");
}

// Phase 2: our structural checks of the bytes (format_checks.hpp), before assimp sees them.
io::CheckResult check_format(io::Format format, std::string_view bytes, const std::string& name) {
  switch (format) {
    case io::Format::obj: return io::check_obj(bytes, name);
    case io::Format::off: return io::check_off(bytes, name);
    case io::Format::stl: return io::check_stl(bytes, name);
    case io::Format::ply: return io::check_ply(bytes, name);
  }
  return {};
}

// Phase 3: assimp reads the checked file (OFF: our normalized text). The scene belongs to
// `importer`.
// assimp's default logger is the silent NullLogger; we never create the DefaultLogger, so
// nothing reaches stdout/stderr. No SortByPType: it rejects valid files that contain an empty
// sub-mesh (assimp's own STL/triangle_with_empty_solid.stl); points and lines are skipped below.
// No ValidateDataStructure for the same reason: our checks and check_mesh() cover what it would.
const aiScene& read_scene(Assimp::Importer& importer, const std::filesystem::path& path, io::Format format,
                          const std::string& bytes, const io::CheckResult& checked, const std::string& name) {
  const aiScene* scene = nullptr;
  if (format == io::Format::off) {
    // The checked and normalized text: assimp 5.2 fails on valid COFF files with RGB colours
    // and on comments after values (both in CGAL's mesh_with_colors.off).
    const std::string& text = checked.normalized;
    scene = importer.ReadFileFromMemory(text.data(), text.size(), aiProcess_Triangulate, "off");
  } else if (path.has_extension()) {
    scene = importer.ReadFile(name, aiProcess_Triangulate);  // by path, so OBJ finds its .mtl
  } else {
    // No extension: hand assimp the bytes with the sniffed format as hint.
    const char* hint = format == io::Format::obj ? "obj" : format == io::Format::stl ? "stl" : "ply";
    scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), aiProcess_Triangulate, hint);
  }
  if (scene == nullptr)
    throw InputError(name + ": malformed " + io::format_name(format) + " file: " + importer.GetErrorString());
  return *scene;
}

// Phase 4: the triangles of all sub-meshes in one mesh, exactly equal positions welded when
// `weld` (see PositionKey).
Mesh collect_triangles(const aiScene& scene, bool weld) {
  Mesh mesh;
  std::unordered_map<PositionKey, std::uint32_t, PositionHash> welded;
  std::vector<std::uint32_t> remap;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* sub = scene.mMeshes[m];
    if ((sub->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;  // points or lines only
    remap.assign(sub->mNumVertices, 0);
    for (unsigned v = 0; v < sub->mNumVertices; ++v) {
      const aiVector3D& p = sub->mVertices[v];
      const Vec3 q(p.x, p.y, p.z);
      if (weld) {
        // + 0.0 turns -0.0 into +0.0, so both weld together.
        const PositionKey key{{std::bit_cast<std::uint64_t>(q.x() + 0.0), std::bit_cast<std::uint64_t>(q.y() + 0.0),
                               std::bit_cast<std::uint64_t>(q.z() + 0.0)}};
        const auto [it, inserted] = welded.try_emplace(key, static_cast<std::uint32_t>(mesh.vertices.size()));
        if (inserted) mesh.vertices.push_back(q);
        remap[v] = it->second;
      } else {
        remap[v] = static_cast<std::uint32_t>(mesh.vertices.size());
        mesh.vertices.push_back(q);
      }
    }
    for (unsigned f = 0; f < sub->mNumFaces; ++f) {
      const aiFace& face = sub->mFaces[f];
      if (face.mNumIndices != 3) continue;  // a point or a line among triangles
      Triangle t{};
      for (int c = 0; c < 3; ++c) {
        const unsigned index = face.mIndices[c];
        // Out-of-range here would be assimp's bug, not the file's: still an error, never UB.
        t[c] = index < sub->mNumVertices ? remap[index] : std::numeric_limits<std::uint32_t>::max();
      }
      mesh.triangles.push_back(t);
    }
  }
  return mesh;
}

// Phase 5 (OFF): assimp keeps the file's vertex order, so its single-precision coordinates can
// be swapped for the double values we parsed, after checking that the two agree vertex by vertex.
void restore_precision(const std::vector<std::array<double, 3>>& precise, Mesh& mesh) {
  if (precise.empty() || precise.size() != mesh.vertices.size()) return;
  bool same = true;
  for (std::size_t i = 0; same && i < precise.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      // assimp's fast_atof is not correctly rounded: allow a few float ulps.
      const double p = precise[i][a];
      const double q = mesh.vertices[i][a];
      same = same && (std::isinf(q) ? std::abs(p) >= std::numeric_limits<float>::max()
                                    : std::abs(p - q) <= 4e-7 * std::max(std::abs(p), 1e-30));
    }
  if (same)
    for (std::size_t i = 0; i < precise.size(); ++i) mesh.vertices[i] = Vec3(precise[i][0], precise[i][1], precise[i][2]);
}

}  // namespace

Mesh load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  check_path(path, name);
  const std::string bytes = read_all(path, name);
  if (bytes.find_first_not_of(" \t\r\n") == std::string::npos) throw InputError(name + ": empty file");
  const io::Format format = detect_format(path, bytes, name);
  const io::CheckResult checked = check_format(format, bytes, name);

  Assimp::Importer importer;
  Mesh mesh = collect_triangles(read_scene(importer, path, format, bytes, checked, name), checked.weld);
  restore_precision(checked.precise_vertices, mesh);
  // Phase 6: what assimp made of the file against what the checks expect.
  if (checked.expected_triangles != 0 && mesh.triangles.size() != checked.expected_triangles)
    throw InputError(name + ": cannot triangulate: the file's polygons make " +
                     std::to_string(checked.expected_triangles) + " triangles but assimp produced " +
                     std::to_string(mesh.triangles.size()) + " (non-simple or non-planar polygons?)");
  if (mesh.triangles.empty())
    throw InputError(name + ": no triangles: the file holds no faces (only points, lines or nothing)");
  (void)check_mesh(mesh, name);
  return mesh;
}

}  // namespace tightbvh

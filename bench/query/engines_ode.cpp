// ODE: dCreateTriMesh geoms (OPCODE trees) queried with dCollide. first_hit asks for one
// contact with CONTACTS_UNIMPORTANT (ODE's early-out flag); all_pairs asks for the maximum
// (65535) contacts and reads the triangle pair from each contact's (side1, side2).
#include <ode/ode.h>

#include <cstdarg>
#include <stdexcept>
#include <string>

#include "bench.hpp"

namespace tightbvh::bench {
namespace {

constexpr int kMaxContacts = 0xffff;  // dCollide's count lives in the low 16 bits of the flags

std::size_t& messages() {
  static std::size_t count = 0;
  return count;
}

struct OdeInit {
  OdeInit() {
    dInitODE2(0);
    // ODE reports every contact-cache overflow on stderr; count them instead.
    dSetMessageHandler([](int, const char*, va_list) { ++messages(); });
    dAllocateODEDataForThread(dAllocateMaskAll);
    if (!dCheckConfiguration("ODE_double_precision"))
      throw std::runtime_error("ode-opcode: libode is not double precision; rebuild the adapter for dSINGLE");
  }
};

struct OdeMesh {
  std::vector<double> vertices;
  std::vector<dTriIndex> indices;
  dTriMeshDataID data = nullptr;
  dGeomID geom = nullptr;

  explicit OdeMesh(const Mesh& mesh) {
    for (const Vec3& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
    for (const Triangle& t : mesh.triangles)
      indices.insert(indices.end(), {dTriIndex(t[0]), dTriIndex(t[1]), dTriIndex(t[2])});
    data = dGeomTriMeshDataCreate();
    dGeomTriMeshDataBuildDouble(data, vertices.data(), int(3 * sizeof(double)), int(mesh.vertices.size()),
                                indices.data(), int(indices.size()), int(3 * sizeof(dTriIndex)));
    geom = dCreateTriMesh(nullptr, data, nullptr, nullptr, nullptr);
  }
  OdeMesh(const OdeMesh&) = delete;
  OdeMesh& operator=(const OdeMesh&) = delete;
  ~OdeMesh() {
    dGeomDestroy(geom);
    dGeomTriMeshDataDestroy(data);
  }
};

class OdeAdapter {
 public:
  explicit OdeAdapter(const Input& in) : a_((init(), in.a)), b_(in.b), contacts_(kMaxContacts) {}

  [[nodiscard]] bool first_hit(const Pose& pose) {
    place(pose);
    return dCollide(a_.geom, b_.geom, 1 | CONTACTS_UNIMPORTANT, contacts_.data(), sizeof(dContactGeom)) > 0;
  }

  void all_pairs(const Pose& pose, std::vector<Pair>& out) {
    place(pose);
    const int n = dCollide(a_.geom, b_.geom, kMaxContacts, contacts_.data(), sizeof(dContactGeom));
    const int na = int(a_.indices.size() / 3), nb = int(b_.indices.size() / 3);
    for (int i = 0; i < n; ++i) {
      const dContactGeom& c = contacts_[i];
      // ODE's contact culling merges contacts and then marks their sides -1: no pair to report.
      const int ia = c.g1 == a_.geom ? c.side1 : c.side2, ib = c.g1 == a_.geom ? c.side2 : c.side1;
      if (ia < 0 || ia >= na || ib < 0 || ib >= nb) {
        ++unpaired;
        continue;
      }
      if (c.g1 == a_.geom) out.emplace_back(std::uint32_t(c.side1), std::uint32_t(c.side2));
      else out.emplace_back(std::uint32_t(c.side2), std::uint32_t(c.side1));
    }
    if (n >= kMaxContacts) ++saturated;
  }

  [[nodiscard]] std::string stats() const {
    return std::to_string(unpaired) + " contacts without a triangle pair (side -1) dropped, " +
           std::to_string(saturated) + " queries filled all 65535 contacts, " + std::to_string(messages()) +
           " ODE messages (trimesh contact hash overflow) -- counts over all runs";
  }
  std::size_t unpaired = 0;  // contacts whose sides are not triangle indices
  int saturated = 0;         // queries that filled the whole contact array

 private:
  static void init() { static OdeInit once; }
  void place(const Pose& pose) {
    dMatrix3 r;  // row-major 3x4
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r[4 * i + j] = pose.rotation(i, j);
      r[4 * i + 3] = 0;
    }
    dGeomSetRotation(b_.geom, r);
    dGeomSetPosition(b_.geom, pose.translation.x(), pose.translation.y(), pose.translation.z());
  }

  OdeMesh a_, b_;
  std::vector<dContactGeom> contacts_;
};

}  // namespace

std::vector<EngineInfo> ode_engines() {
  return {{"ode-opcode", true, true,
           "dCollide returns at most 65535 contacts, merged by ODE's contact culling; pairs are the (side1, side2) of the contacts",
           [](const Input& in) { return prepare([&] { return std::make_unique<OdeAdapter>(in); }); }}};
}

}  // namespace tightbvh::bench

// Our engines (tightbvh-*), our trees inside FCL (fcl-export-*), and the reference.
#include <chrono>
#include <optional>
#include <string>
#include <type_traits>

#include "fcl_adapter.hpp"
#include "tightbvh/build.hpp"
#include "tightbvh/closed.hpp"
#include "tightbvh/collide.hpp"
#include "tightbvh/distance.hpp"
#include "tightbvh/fcl/export.hpp"
#include "tightbvh/model.hpp"
#include "tightbvh/query_cache.hpp"

namespace tightbvh::bench {
namespace {

// Single-threaded builds: FCL, Bullet and ODE build on one thread, so build times compare.
Tree build_tree(const Mesh& mesh, const Fitter& fitter) {
  BuildOptions options;
  options.fitter = fitter;
  options.threads = 1;
  return build(mesh, options);
}

// A Model per mesh (model.hpp), as an application holds one: the tree, its wide nodes (which
// all_pairs descends) and the mesh's closedness (for solid queries), all built and timed here.
ModelPtr build_model(const Mesh& mesh, const Fitter& fitter) {
  BuildOptions options;
  options.fitter = fitter;
  options.threads = 1;
  return make_model(mesh, options);
}

class TightbvhAdapter {
 public:
  TightbvhAdapter(const Input& in, const Fitter& fitter)
      : a_(build_model(in.a, fitter)), b_(build_model(in.b, fitter)), margin_(kMarginOfScale * in.scale) {}

  [[nodiscard]] bool first_hit(const Pose& pose) const {
    return collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::first_hit}, workspace_).hit;
  }
  void all_pairs(const Pose& pose, std::vector<Pair>& out) const {
    const QueryResult r = collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::all_pairs}, workspace_);
    for (const TrianglePair& p : r.pairs) out.emplace_back(p.a, p.b);
  }
  void margin_pairs(const Pose& pose, std::vector<Pair>& out) const {
    const QueryResult r =
        collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::all_pairs, .margin = margin_}, workspace_);
    for (const TrianglePair& p : r.pairs) out.emplace_back(p.a, p.b);
  }
  [[nodiscard]] double distance(const Pose& pose) const {
    return tightbvh::distance(*a_, Pose::identity(), *b_, pose, {}, workspace_).distance;
  }
  [[nodiscard]] const Tree& a() const { return a_->tree(); }
  [[nodiscard]] const Tree& b() const { return b_->tree(); }
  [[nodiscard]] const Mesh& ma() const { return a_->mesh(); }
  [[nodiscard]] const Mesh& mb() const { return b_->mesh(); }
  // An open mesh throws here, on the first call (the checked warm-up pass).
  [[nodiscard]] bool solid_hit(const Pose& pose) const {
    return collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::first_hit, .solid = true}, workspace_).hit;
  }

 private:
  ModelPtr a_, b_;
  double margin_;
  // Scratch reused by every query of this engine (engines run on one thread); mutable because
  // the queries are logically const.
  mutable QueryWorkspace workspace_;
};

// The same models and queries through a QueryCache, one cache per mode, so each mode's sequence
// of poses runs as a simulation loop would: first_hit tries the last hit's triangle pair first,
// all_pairs is the wide descent (model.hpp). Distance queries are cold.
class TightbvhCachedAdapter {
 public:
  TightbvhCachedAdapter(const Input& in, const Fitter& fitter)
      : a_(build_model(in.a, fitter)), b_(build_model(in.b, fitter)), margin_(kMarginOfScale * in.scale) {}

  [[nodiscard]] bool first_hit(const Pose& pose) const {
    const QueryResult r = collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::first_hit}, first_);
    hits_ += r.hit;
    witnessed_ += r.hit && r.stats.box_tests == 0;
    return r.hit;
  }
  void all_pairs(const Pose& pose, std::vector<Pair>& out) const {
    const QueryResult r = collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::all_pairs}, all_);
    for (const TrianglePair& p : r.pairs) out.emplace_back(p.a, p.b);
  }
  void margin_pairs(const Pose& pose, std::vector<Pair>& out) const {
    const QueryResult r =
        collide(*a_, Pose::identity(), *b_, pose, {.mode = QueryMode::all_pairs, .margin = margin_}, margin_cache_);
    for (const TrianglePair& p : r.pairs) out.emplace_back(p.a, p.b);
  }
  [[nodiscard]] double distance(const Pose& pose) const {
    return tightbvh::distance(*a_, Pose::identity(), *b_, pose, {}, workspace_).distance;
  }
  [[nodiscard]] std::string stats() const {
    return "QueryCache: first_hit hits answered by last hit's triangle pair: " + std::to_string(witnessed_) + " of " +
           std::to_string(hits_);
  }

 private:
  ModelPtr a_, b_;
  double margin_;
  mutable QueryCache first_, all_, margin_cache_;
  mutable QueryWorkspace workspace_;
  mutable std::uint64_t hits_ = 0, witnessed_ = 0;
};

EngineInfo cached(const std::string& name, Fitter fitter) {
  EngineInfo info{name, true, true, "",
                  [fitter](const Input& in) {
                    return prepare([&] { return std::make_unique<TightbvhCachedAdapter>(in, fitter); });
                  },
                  true, true};
  info.coherent = true;
  return info;
}

EngineInfo ours(const std::string& name, Fitter fitter) {
  return {name, true, true, "",
          [fitter](const Input& in) { return prepare([&] { return std::make_unique<TightbvhAdapter>(in, fitter); }); },
          true, true, true};
}

// Our tree (fitter `method` everywhere, also below our leaves) exported into FCL's BVHModel<OBB>.
EngineInfo exported(const std::string& name, FitMethod method) {
  return {name, true, true, "",
          [method](const Input& in) {
            return prepare([&] {
              FclExportOptions options;
              options.fit.method = method;
              using Obb = fcl::OBB<double>;
              return std::make_unique<FclAdapter<Obb>>(to_fcl(build_tree(in.a, method), in.a, options),
                                                       to_fcl(build_tree(in.b, method), in.b, options));
            });
          }};
}

// Our approx tree exported into FCL's BVHModel<RSS> or <OBBRSS> (RSS fitted to our boxes),
// queried by FCL's own fcl::distance. RSS models answer distances only.
template <class BV>
EngineInfo exported_distance(const std::string& name, bool collide) {
  return {name, collide, collide, collide ? "" : "distance mode only",
          [](const Input& in) {
            return prepare([&] {
              FclExportOptions options;
              options.fit.method = FitMethod::approx;
              const Tree ta = build_tree(in.a, FitMethod::approx), tb = build_tree(in.b, FitMethod::approx);
              if constexpr (std::is_same_v<BV, fcl::RSS<double>>)
                return std::make_unique<FclAdapter<BV>>(to_fcl_rss(ta, in.a, options), to_fcl_rss(tb, in.b, options));
              else
                return std::make_unique<FclAdapter<BV>>(to_fcl_obbrss(ta, in.a, options),
                                                        to_fcl_obbrss(tb, in.b, options));
            });
          },
          true};
}

// Brute force (every triangle pair) is affordable up to this many pairs per query.
constexpr double kBruteForcePairs = 2e6;

}  // namespace

std::vector<EngineInfo> tightbvh_engines() {
  return {ours("tightbvh-aabb", FitMethod::aabb),
          ours("tightbvh-pca", FitMethod::pca),
          ours("tightbvh-approx", FitMethod::approx),
          ours("tightbvh-auto", AutoFit{}),
          // auto with independent node searches (each node on its own, approx from 2048 triangles,
          // thresholds growing above 131,072): the baseline of search_from_parent in the same run.
          ours("tightbvh-auto-unseeded",
               AutoFit{.tight_min_triangles = 2048, .scale_above = 131072, .search_from_parent = false}),
          cached("tightbvh-approx-qc", FitMethod::approx),
          cached("tightbvh-auto-qc", AutoFit{}),
          exported("fcl-export-pca", FitMethod::pca),
          exported("fcl-export-approx", FitMethod::approx),
          exported_distance<fcl::RSS<double>>("fcl-export-rss", false),
          exported_distance<fcl::OBBRSS<double>>("fcl-export-obbrss", true)};
}

struct Reference::Impl {
  const Input& in;
  bool brute = false;
  Tree a, b;
  QueryWorkspace workspace;
  std::optional<Closedness> closed_a, closed_b;  // solid: computed on first use

  [[nodiscard]] QueryOptions solid() {
    if (!closed_a) closed_a = check_closed(in.a), closed_b = check_closed(in.b);
    return {.mode = QueryMode::first_hit, .solid = true, .closed_a = &*closed_a, .closed_b = &*closed_b};
  }
};

Reference::Reference(const Input& in) : impl_(new Impl{in, false, {}, {}, {}, {}, {}}) {
  impl_->brute = double(in.a.triangles.size()) * double(in.b.triangles.size()) <= kBruteForcePairs;
  // Axis-aligned boxes: the simplest boxes, so the reference does not lean on a tight fitter.
  impl_->a = build_tree(in.a, FitMethod::aabb);
  impl_->b = build_tree(in.b, FitMethod::aabb);
}
Reference::~Reference() = default;

bool Reference::collides(const Pose& p) const {
  return collide(impl_->a, impl_->in.a, Pose::identity(), impl_->b, impl_->in.b, p, {.mode = QueryMode::first_hit},
                 impl_->workspace)
      .hit;
}

std::vector<Pair> Reference::pairs(const Pose& p) const {
  const QueryOptions all{.mode = QueryMode::all_pairs};
  const QueryResult r = impl_->brute ? collide_brute_force(impl_->in.a, Pose::identity(), impl_->in.b, p, all)
                                     : collide(impl_->a, impl_->in.a, Pose::identity(), impl_->b, impl_->in.b, p, all, impl_->workspace);
  std::vector<Pair> out;
  out.reserve(r.pairs.size());
  for (const TrianglePair& t : r.pairs) out.emplace_back(t.a, t.b);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

double Reference::distance(const Pose& p) const {
  return impl_->brute ? distance_brute_force(impl_->in.a, Pose::identity(), impl_->in.b, p).distance
                      : tightbvh::distance(impl_->a, impl_->in.a, Pose::identity(), impl_->b, impl_->in.b, p, {},
                                           impl_->workspace)
                            .distance;
}

double Reference::brute_force_distance(const Pose& p) const {
  return distance_brute_force(impl_->in.a, Pose::identity(), impl_->in.b, p).distance;
}

std::vector<Pair> Reference::margin_pairs(const Pose& p) const {
  const QueryOptions options{.mode = QueryMode::all_pairs, .margin = kMarginOfScale * impl_->in.scale};
  const QueryResult r = impl_->brute ? collide_brute_force(impl_->in.a, Pose::identity(), impl_->in.b, p, options)
                                     : collide(impl_->a, impl_->in.a, Pose::identity(), impl_->b, impl_->in.b, p,
                                               options, impl_->workspace);
  std::vector<Pair> out;
  for (const TrianglePair& t : r.pairs) out.emplace_back(t.a, t.b);
  return out;  // sorted and unique already
}

bool Reference::solid_collides(const Pose& p) const {
  const QueryOptions options = impl_->solid();
  return impl_->brute ? collide_brute_force(impl_->in.a, Pose::identity(), impl_->in.b, p, options).hit
                      : collide(impl_->a, impl_->in.a, Pose::identity(), impl_->b, impl_->in.b, p, options,
                                impl_->workspace)
                            .hit;
}

bool Reference::contained(const Pose& p) const {
  const QueryOptions options = impl_->solid();
  return collide(impl_->a, impl_->in.a, Pose::identity(), impl_->b, impl_->in.b, p, options, impl_->workspace).inside !=
         Inside::none;
}

std::string Reference::description() const {
  return impl_->brute ? "tightbvh collide_brute_force / distance_brute_force (every triangle pair)"
                      : "tightbvh collide all_pairs / distance on AABB trees (verified against brute force by the "
                        "collide and distance tests; meshes too large for brute force here)";
}

}  // namespace tightbvh::bench

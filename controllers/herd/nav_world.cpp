#include "animrt/controllers/herd/nav_world.hpp"

#include <DetourCommon.h>
#include <DetourNavMesh.h>
#include <DetourNavMeshBuilder.h>
#include <DetourNavMeshQuery.h>
#include <DetourTileCache.h>
#include <DetourTileCacheBuilder.h>
#include <Recast.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace animrt::herd {
namespace {

constexpr unsigned short kWalkFlag = 1;
constexpr int kMaxLayersPerTile = 8;
constexpr int kExpectedLayersPerTile = 4;
constexpr int kMaxPathPolys = 4096;
constexpr int kMaxQueryNodes = 8192;

// Tiles are kept uncompressed: the worlds are small, and a byte copy is
// all the tile cache needs to store and restore a layer.
struct PassThroughCompressor final : dtTileCacheCompressor {
  int maxCompressedSize(const int bufferSize) override { return bufferSize; }
  dtStatus compress(const unsigned char* buffer, const int bufferSize, unsigned char* compressed,
                    const int maxCompressedSize, int* compressedSize) override {
    if (bufferSize > maxCompressedSize) return DT_FAILURE | DT_BUFFER_TOO_SMALL;
    std::memcpy(compressed, buffer, static_cast<std::size_t>(bufferSize));
    *compressedSize = bufferSize;
    return DT_SUCCESS;
  }
  dtStatus decompress(const unsigned char* compressed, const int compressedSize,
                      unsigned char* buffer, const int maxBufferSize, int* bufferSize) override {
    if (compressedSize > maxBufferSize) return DT_FAILURE | DT_BUFFER_TOO_SMALL;
    std::memcpy(buffer, compressed, static_cast<std::size_t>(compressedSize));
    *bufferSize = compressedSize;
    return DT_SUCCESS;
  }
};

// Every walkable polygon gets the walk flag: the default query filter
// includes only polygons with a flag set, so without this nothing is
// walkable.
struct WalkFlags final : dtTileCacheMeshProcess {
  void process(dtNavMeshCreateParams* params, unsigned char* polyAreas,
               unsigned short* polyFlags) override {
    for (int i = 0; i < params->polyCount; ++i) {
      polyFlags[i] = polyAreas[i] == DT_TILECACHE_WALKABLE_AREA ? kWalkFlag : 0;
    }
  }
};

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error("navigation mesh: " + what);
}

unsigned next_pow2(unsigned v) {
  unsigned p = 1;
  while (p < v) p <<= 1;
  return p;
}
unsigned ilog2(unsigned v) {
  unsigned r = 0;
  while ((1u << (r + 1)) <= v) ++r;
  return r;
}

std::array<Vec2, 4> box_corners(const Box& b) {
  const Vec2 ax = heading_vector(b.yaw_rad) * (b.size.x / 2);
  const Vec2 ay = heading_vector(b.yaw_rad + M_PI / 2) * (b.size.y / 2);
  return {b.center - ax - ay, b.center + ax - ay, b.center + ax + ay, b.center - ax + ay};
}

// The input geometry in Recast coordinates, with an area per triangle.
struct Geometry {
  std::vector<float> verts;
  std::vector<int> tris;
  std::vector<unsigned char> areas;
  float ymin = 0.0f, ymax = 0.0f;

  int vert(Vec2 p, double z) {
    const auto v = NavWorld::to_recast(p, z);
    verts.insert(verts.end(), v.begin(), v.end());
    ymin = std::min(ymin, v[1]);
    ymax = std::max(ymax, v[1]);
    return static_cast<int>(verts.size() / 3 - 1);
  }
  void tri(int a, int b, int c, unsigned char area) {
    tris.insert(tris.end(), {a, b, c});
    areas.push_back(area);
  }
};

}  // namespace

struct NavWorld::Parts {
  dtTileCacheAlloc alloc;  // plain dtAlloc/dtFree: rebuilds are rare and off the real-time cycle
  PassThroughCompressor compressor;
  WalkFlags mesh_process;
  dtQueryFilter filter;
  Geometry geometry;
  std::vector<std::array<float, 3>> wall_polys;  // 4 corners per wall, flattened below
  rcContext ctx{false};
  float bmin[3] = {}, bmax[3] = {};
  int tiles_x = 0, tiles_y = 0;
};

double NavWorld::distance_to_box(Vec2 p, const Box& b) {
  const Vec2 d = p - b.center;
  const Vec2 ax = heading_vector(b.yaw_rad);
  const double lx = std::abs(dot(d, ax)) - b.size.x / 2;
  const double ly = std::abs(cross(ax, d)) - b.size.y / 2;
  return std::hypot(std::max(lx, 0.0), std::max(ly, 0.0));
}

NavWorld::NavWorld(NavWorldConfig config) : config_(std::move(config)), parts_(new Parts) {
  const Rect& r = config_.bounds;
  if (!(r.xmax > r.xmin && r.ymax > r.ymin)) fail("the ground rectangle is empty");
  if (!(config_.cell_size_m > 0.0 && config_.cell_height_m > 0.0))
    fail("cell sizes must be positive");
  if (config_.triangles.size() % 3 != 0)
    fail("the triangle soup's point count is not a multiple of 3");
  if (config_.tile_cells < 16 || config_.tile_cells > 255) fail("tile_cells must be in [16, 255]");
  parts_->filter.setIncludeFlags(kWalkFlag);
  parts_->filter.setExcludeFlags(0);

  Geometry& g = parts_->geometry;
  {
    const int a = g.vert({r.xmin, r.ymin}, 0), b = g.vert({r.xmax, r.ymin}, 0);
    const int c = g.vert({r.xmax, r.ymax}, 0), d = g.vert({r.xmin, r.ymax}, 0);
    g.tri(a, b, c, RC_WALKABLE_AREA);
    g.tri(a, c, d, RC_WALKABLE_AREA);
  }
  for (const Box& w : config_.walls) {
    const auto cs = box_corners(w);
    int lo[4], hi[4];
    for (int i = 0; i < 4; ++i) {
      lo[i] = g.vert(cs[i], 0.0);
      hi[i] = g.vert(cs[i], config_.wall_height_m);
      parts_->wall_polys.push_back(NavWorld::to_recast(cs[i]));
    }
    g.tri(hi[0], hi[1], hi[2], RC_NULL_AREA);
    g.tri(hi[0], hi[2], hi[3], RC_NULL_AREA);
    for (int i = 0; i < 4; ++i) {
      const int j = (i + 1) % 4;
      g.tri(lo[i], lo[j], hi[j], RC_NULL_AREA);
      g.tri(lo[i], hi[j], hi[i], RC_NULL_AREA);
    }
  }
  if (!config_.triangles.empty()) {
    const int first_tri = static_cast<int>(g.areas.size());
    for (std::size_t i = 0; i < config_.triangles.size(); i += 3) {
      int ids[3];
      for (int k = 0; k < 3; ++k) {
        const auto& p = config_.triangles[i + static_cast<std::size_t>(k)];
        ids[k] = g.vert({p[0], p[1]}, p[2]);
      }
      g.tri(ids[0], ids[1], ids[2], RC_NULL_AREA);
    }
    const int n = static_cast<int>(g.areas.size()) - first_tri;
    rcMarkWalkableTriangles(&parts_->ctx, 45.0f, g.verts.data(),
                            static_cast<int>(g.verts.size() / 3), g.tris.data() + 3 * first_tri, n,
                            g.areas.data() + first_tri);
  }

  const float cs = static_cast<float>(config_.cell_size_m);
  parts_->bmin[0] = static_cast<float>(r.xmin);
  parts_->bmin[1] = g.ymin - 0.5f;
  parts_->bmin[2] = static_cast<float>(-r.ymax);
  parts_->bmax[0] = static_cast<float>(r.xmax);
  parts_->bmax[1] = g.ymax + 0.5f;
  parts_->bmax[2] = static_cast<float>(-r.ymin);
  const int gw = static_cast<int>(std::ceil((r.xmax - r.xmin) / config_.cell_size_m));
  const int gh = static_cast<int>(std::ceil((r.ymax - r.ymin) / config_.cell_size_m));
  const int ts = config_.tile_cells;
  parts_->tiles_x = (gw + ts - 1) / ts;
  parts_->tiles_y = (gh + ts - 1) / ts;

  dtTileCacheParams tcp{};
  dtVcopy(tcp.orig, parts_->bmin);
  tcp.cs = cs;
  tcp.ch = static_cast<float>(config_.cell_height_m);
  tcp.width = ts;
  tcp.height = ts;
  tcp.walkableHeight = static_cast<float>(config_.agent_height_m);
  tcp.walkableRadius = static_cast<float>(config_.agent_radius_m);
  tcp.walkableClimb = static_cast<float>(config_.agent_climb_m);
  tcp.maxSimplificationError = 1.3f;
  tcp.maxTiles = parts_->tiles_x * parts_->tiles_y * kExpectedLayersPerTile;
  tcp.maxObstacles = std::max(config_.max_obstacles, static_cast<int>(config_.moving.size()));
  tile_cache_ = dtAllocTileCache();
  if (!tile_cache_ || dtStatusFailed(tile_cache_->init(&tcp, &parts_->alloc, &parts_->compressor,
                                                       &parts_->mesh_process))) {
    fail("could not initialise the tile cache");
  }

  const unsigned tile_bits =
      std::min(ilog2(next_pow2(static_cast<unsigned>(parts_->tiles_x * parts_->tiles_y *
                                                     kExpectedLayersPerTile))),
               14u);
  dtNavMeshParams nmp{};
  dtVcopy(nmp.orig, parts_->bmin);
  nmp.tileWidth = static_cast<float>(ts) * cs;
  nmp.tileHeight = static_cast<float>(ts) * cs;
  nmp.maxTiles = 1 << tile_bits;
  nmp.maxPolys = 1 << (22 - tile_bits);
  navmesh_ = dtAllocNavMesh();
  if (!navmesh_ || dtStatusFailed(navmesh_->init(&nmp)))
    fail("could not initialise the navigation mesh");
  query_ = dtAllocNavMeshQuery();
  if (!query_ || dtStatusFailed(query_->init(navmesh_, kMaxQueryNodes)))
    fail("could not initialise the query");

  build_tiles();
  obstacles_.resize(config_.moving.size());
}

NavWorld::~NavWorld() {
  dtFreeNavMeshQuery(query_);
  dtFreeNavMesh(navmesh_);
  dtFreeTileCache(tile_cache_);
}

const dtQueryFilter& NavWorld::filter() const { return parts_->filter; }

void NavWorld::build_tiles() {
  Parts& p = *parts_;
  const Geometry& g = p.geometry;
  rcConfig cfg{};
  cfg.cs = static_cast<float>(config_.cell_size_m);
  cfg.ch = static_cast<float>(config_.cell_height_m);
  cfg.walkableSlopeAngle = 45.0f;
  cfg.walkableHeight = static_cast<int>(std::ceil(config_.agent_height_m / config_.cell_height_m));
  cfg.walkableClimb = static_cast<int>(std::floor(config_.agent_climb_m / config_.cell_height_m));
  cfg.walkableRadius =
      static_cast<int>(std::ceil(config_.agent_radius_m / config_.cell_size_m - 1e-6));
  cfg.maxSimplificationError = 1.3f;
  cfg.tileSize = config_.tile_cells;
  cfg.borderSize = cfg.walkableRadius + 3;
  cfg.width = cfg.tileSize + 2 * cfg.borderSize;
  cfg.height = cfg.tileSize + 2 * cfg.borderSize;
  const float tile_m = static_cast<float>(cfg.tileSize) * cfg.cs;
  const float border_m = static_cast<float>(cfg.borderSize) * cfg.cs;
  const int nverts = static_cast<int>(g.verts.size() / 3);
  const int ntris = static_cast<int>(g.areas.size());

  for (int ty = 0; ty < p.tiles_y; ++ty) {
    for (int tx = 0; tx < p.tiles_x; ++tx) {
      cfg.bmin[0] = p.bmin[0] + static_cast<float>(tx) * tile_m - border_m;
      cfg.bmin[1] = p.bmin[1];
      cfg.bmin[2] = p.bmin[2] + static_cast<float>(ty) * tile_m - border_m;
      cfg.bmax[0] = p.bmin[0] + static_cast<float>(tx + 1) * tile_m + border_m;
      cfg.bmax[1] = p.bmax[1];
      cfg.bmax[2] = p.bmin[2] + static_cast<float>(ty + 1) * tile_m + border_m;

      // Owned intermediate results of one tile, freed on every exit.
      struct Scratch {
        rcHeightfield* solid = rcAllocHeightfield();
        rcCompactHeightfield* chf = rcAllocCompactHeightfield();
        rcHeightfieldLayerSet* lset = rcAllocHeightfieldLayerSet();
        ~Scratch() {
          rcFreeHeightField(solid);
          rcFreeCompactHeightfield(chf);
          rcFreeHeightfieldLayerSet(lset);
        }
      } s;
      if (!s.solid || !s.chf || !s.lset) fail("out of memory");
      if (!rcCreateHeightfield(&p.ctx, *s.solid, cfg.width, cfg.height, cfg.bmin, cfg.bmax, cfg.cs,
                               cfg.ch) ||
          !rcRasterizeTriangles(&p.ctx, g.verts.data(), nverts, g.tris.data(), g.areas.data(),
                                ntris, *s.solid, cfg.walkableClimb)) {
        fail("could not rasterize tile " + std::to_string(tx) + "," + std::to_string(ty));
      }
      rcFilterLowHangingWalkableObstacles(&p.ctx, cfg.walkableClimb, *s.solid);
      rcFilterLedgeSpans(&p.ctx, cfg.walkableHeight, cfg.walkableClimb, *s.solid);
      rcFilterWalkableLowHeightSpans(&p.ctx, cfg.walkableHeight, *s.solid);
      if (!rcBuildCompactHeightfield(&p.ctx, cfg.walkableHeight, cfg.walkableClimb, *s.solid,
                                     *s.chf)) {
        fail("could not build the compact heightfield");
      }
      // The walls' footprints (up to their height: a deck above stays
      // walkable) are unwalkable before erosion, so the mesh keeps a
      // figure's radius away from them.
      for (std::size_t w = 0; w < p.wall_polys.size(); w += 4) {
        float poly[12];
        for (int k = 0; k < 4; ++k)
          std::memcpy(poly + 3 * k, p.wall_polys[w + k].data(), 3 * sizeof(float));
        rcMarkConvexPolyArea(&p.ctx, poly, 4, p.bmin[1], static_cast<float>(config_.wall_height_m),
                             RC_NULL_AREA, *s.chf);
      }
      if (!rcErodeWalkableArea(&p.ctx, cfg.walkableRadius, *s.chf)) fail("could not erode");
      if (!rcBuildHeightfieldLayers(&p.ctx, *s.chf, cfg.borderSize, cfg.walkableHeight, *s.lset)) {
        fail("could not build the heightfield layers");
      }
      for (int i = 0; i < std::min(s.lset->nlayers, kMaxLayersPerTile); ++i) {
        const rcHeightfieldLayer& layer = s.lset->layers[i];
        dtTileCacheLayerHeader header{};
        header.magic = DT_TILECACHE_MAGIC;
        header.version = DT_TILECACHE_VERSION;
        header.tx = tx;
        header.ty = ty;
        header.tlayer = i;
        dtVcopy(header.bmin, layer.bmin);
        dtVcopy(header.bmax, layer.bmax);
        header.width = static_cast<unsigned char>(layer.width);
        header.height = static_cast<unsigned char>(layer.height);
        header.minx = static_cast<unsigned char>(layer.minx);
        header.maxx = static_cast<unsigned char>(layer.maxx);
        header.miny = static_cast<unsigned char>(layer.miny);
        header.maxy = static_cast<unsigned char>(layer.maxy);
        header.hmin = static_cast<unsigned short>(layer.hmin);
        header.hmax = static_cast<unsigned short>(layer.hmax);
        unsigned char* data = nullptr;
        int size = 0;
        if (dtStatusFailed(dtBuildTileCacheLayer(&p.compressor, &header, layer.heights, layer.areas,
                                                 layer.cons, &data, &size))) {
          fail("could not build a tile layer");
        }
        if (dtStatusFailed(
                tile_cache_->addTile(data, size, DT_COMPRESSEDTILE_FREE_DATA, nullptr))) {
          dtFree(data);
          fail("tile budget exceeded");
        }
      }
    }
  }
  for (int ty = 0; ty < p.tiles_y; ++ty) {
    for (int tx = 0; tx < p.tiles_x; ++tx) {
      if (dtStatusFailed(tile_cache_->buildNavMeshTilesAt(tx, ty, navmesh_))) {
        fail("could not build navigation tiles at " + std::to_string(tx) + "," +
             std::to_string(ty));
      }
    }
  }
}

void NavWorld::add_obstacle(std::size_t i) {
  const Box& b = config_.moving[i].footprint;
  // Tile-cache obstacles are not eroded: grow the box by the figure radius.
  const auto c = to_recast(b.center, 0.5 * config_.wall_height_m);
  const float he[3] = {static_cast<float>(b.size.x / 2 + config_.agent_radius_m),
                       static_cast<float>(config_.wall_height_m + 1.0),
                       static_cast<float>(b.size.y / 2 + config_.agent_radius_m)};
  dtObstacleRef ref = 0;
  if (dtStatusFailed(
          tile_cache_->addBoxObstacle(c.data(), he, static_cast<float>(b.yaw_rad), &ref))) {
    fail("could not add an obstacle");
  }
  obstacles_[i].ref = ref;
}

void NavWorld::flush() {
  for (int k = 0; k < 1000; ++k) {
    bool done = false;
    tile_cache_->update(0.0f, navmesh_, &done);
    if (done) return;
  }
}

void NavWorld::update(double t, std::span<const Agent> agents) {
  bool changed = false;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const MovingObstacle& m = config_.moving[i];
    ObstacleState& st = obstacles_[i];
    const bool want_down = m.time_in_period(t) < m.down_fraction * m.period_s;
    if (!want_down) {
      st.deferred_this_window = false;
      st.dropped_this_window = false;
      if (st.down) {
        tile_cache_->removeObstacle(st.ref);
        st.down = false;
        changed = true;
      }
      continue;
    }
    if (st.down || st.dropped_this_window) continue;
    bool blocked = false;
    for (const Agent& a : agents) {
      const double keep = std::max(a.radius, config_.agent_radius_m) + 0.05;
      if (distance_to_box(a.position, m.footprint) < keep) {
        blocked = true;
        break;
      }
    }
    if (blocked) {
      if (!st.deferred_this_window) ++deferred_drops_;
      st.deferred_this_window = true;
      continue;
    }
    add_obstacle(i);
    st.down = true;
    st.dropped_this_window = true;
    ++drops_;
    changed = true;
  }
  if (changed) flush();
}

std::optional<Vec2> NavWorld::nearest_on_mesh(Vec2 p, double snap_m) const {
  const auto c = to_recast(p);
  const float ext[3] = {static_cast<float>(snap_m), 2.0f, static_cast<float>(snap_m)};
  dtPolyRef ref = 0;
  float nearest[3];
  if (dtStatusFailed(query_->findNearestPoly(c.data(), ext, &parts_->filter, &ref, nearest)) ||
      !ref) {
    return std::nullopt;
  }
  const Vec2 q = from_recast(nearest);
  if (norm(q - p) > snap_m) return std::nullopt;
  return q;
}

bool NavWorld::on_mesh(Vec2 p, double tol_m) const {
  const auto q = nearest_on_mesh(p, tol_m + config_.cell_size_m);
  return q && norm(*q - p) <= tol_m;
}

bool NavWorld::in_wall(Vec2 p, double radius_m) const {
  for (const Box& w : config_.walls) {
    const double d = distance_to_box(p, w);
    if (d <= 0.0 || d < radius_m) return true;
  }
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    if (!obstacles_[i].down) continue;
    const double d = distance_to_box(p, config_.moving[i].footprint);
    if (d <= 0.0 || d < radius_m) return true;
  }
  return false;
}

namespace {
struct PathResult {
  bool complete = false;
  double length = 0.0;
};

// The shortest path's corners go to `corners` when given.
PathResult find_path(dtNavMeshQuery& q, const dtQueryFilter& filter, Vec2 from, Vec2 to,
                     double snap_m, bool want_length, std::vector<Vec2>* corners = nullptr) {
  const float ext[3] = {static_cast<float>(snap_m), 2.0f, static_cast<float>(snap_m)};
  const auto a = NavWorld::to_recast(from);
  const auto b = NavWorld::to_recast(to);
  dtPolyRef ra = 0, rb = 0;
  float pa[3], pb[3];
  q.findNearestPoly(a.data(), ext, &filter, &ra, pa);
  q.findNearestPoly(b.data(), ext, &filter, &rb, pb);
  if (!ra || !rb) return {};
  std::vector<dtPolyRef> path(kMaxPathPolys);
  int n = 0;
  const dtStatus st = q.findPath(ra, rb, pa, pb, &filter, path.data(), &n, kMaxPathPolys);
  if (dtStatusFailed(st) || n == 0 || path[static_cast<std::size_t>(n - 1)] != rb ||
      dtStatusDetail(st, DT_PARTIAL_RESULT)) {
    return {};
  }
  PathResult r{true, 0.0};
  if (!want_length && !corners) return r;
  std::vector<float> pts(3 * kMaxPathPolys);
  int np = 0;
  q.findStraightPath(pa, pb, path.data(), n, pts.data(), nullptr, nullptr, &np, kMaxPathPolys);
  for (int i = 1; i < np; ++i) {
    r.length += norm(NavWorld::from_recast(&pts[3 * static_cast<std::size_t>(i)]) -
                     NavWorld::from_recast(&pts[3 * static_cast<std::size_t>(i - 1)]));
  }
  if (corners) {
    corners->clear();
    for (int i = 0; i < np; ++i)
      corners->push_back(NavWorld::from_recast(&pts[3 * static_cast<std::size_t>(i)]));
  }
  return r;
}
}  // namespace

bool NavWorld::has_path(Vec2 from, Vec2 to, double snap_m) const {
  return find_path(*query_, parts_->filter, from, to, snap_m, false).complete;
}

std::optional<double> NavWorld::path_length(Vec2 from, Vec2 to, double snap_m) const {
  const PathResult r = find_path(*query_, parts_->filter, from, to, snap_m, true);
  if (!r.complete) return std::nullopt;
  return r.length;
}

std::optional<std::vector<Vec2>> NavWorld::path(Vec2 from, Vec2 to, double snap_m) const {
  std::vector<Vec2> corners;
  if (!find_path(*query_, parts_->filter, from, to, snap_m, false, &corners).complete)
    return std::nullopt;
  return corners;
}

}  // namespace animrt::herd

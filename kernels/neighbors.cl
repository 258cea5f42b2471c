// Fixed-radius neighbour search without neighbour lists. A work-item owns VW query points
// (one per lane) and walks candidates that cover every point within r of each of them; the
// caller keeps a candidate for a lane when the lane's mask is set and the squared distance is
// at most r^2.
// - Organized frames: the queries are VW horizontally adjacent pixels. The walk visits, row by
//   row, the offsets t of a pixel window; at offset t lane q's candidate is pixel (row,
//   col_q + t), so one unaligned vector load serves all lanes. The window is an ellipse that
//   holds every point within r under the pinhole model (see window_radius).
// - Unorganized clouds: the queries are VW consecutive points of the cloud sorted by grid
//   slot (grid_build.cl), so mostly in one or two neighbouring cells (edge >= r). The walk
//   visits the points of the union of their 27-cell stencils, row by row of cells (see
//   cell_slot); a candidate is one point, broadcast to all lanes.

// The cells of an unorganized cloud: edge 1 / inv_cell (>= r). A cell's slot in the table of
// slot_start is its index in a dense box of cells when the cloud's bounding box is small
// enough (slot_mask == 0), else a hash (slot_mask = table size - 1, a power of two).
typedef struct {
  float inv_cell;  // 1/m
  uint slot_mask;
  int x0, y0, z0;  // dense: the cell of slot 0 (the box's lowest cell minus one per axis)
  int nx, ny;      // dense: cells along x and y
} Grid;

// Kernel parameters of a Grid, and the Grid they make.
#define GRID_PARAMS \
  float inv_cell, uint slot_mask, int grid_x0, int grid_y0, int grid_z0, int grid_nx, int grid_ny
#define GRID_FROM_PARAMS \
  { inv_cell, slot_mask, grid_x0, grid_y0, grid_z0, grid_nx, grid_ny }

typedef struct {
  // Organized frame: row-major image of width x height pixels; focal lengths in pixels; how
  // far (pixels) points typically sit from the pixels their positions project to (the host's
  // FrameIntrinsics::slack).
  int width, height;
  float fx, fy, slack;
  // Grid: slot_start[s] .. slot_start[s + 1] is the range of slot s in the sorted arrays.
  __global const uint* slot_start;
  Grid grid;
  int count;     // sorted (valid) points
  float radius;  // m
} Search;

// The query points of one work-item.
typedef struct {
  V3 p;       // positions (m)
  vint ok;    // lanes holding a valid point
  int first;  // search-order index of lane 0
  int lanes;  // lanes that exist (a row's or the cloud's last work-item may own fewer)
} Queries;

// The walk over candidates, one index range at a time: lane 0's candidates k in [lo, hi) of
// one image row (organized; lane q's is k + q), or the points of a run of grid slots, each
// broadcast to the lanes being walked. Use through FOR_EACH_CANDIDATE.
typedef struct {
  int lo, hi;
  vint ok;
  // Organized: rows row .. row_last; the query row and lane 0's column; the ellipse's
  // half-axes (pixels), or the whole image; whether the current row range reaches past an
  // image edge for some lane (then each candidate's column is checked).
  int row, row_last, row_q, c0;
  float rx, ry;
  bool full, edge;
  // Grid: lanes not yet walked and the lanes walked now; the current stencil's point ranges
  // (at most 32: 16 rows of cells, each split at most once at the table's end) and the next
  // one to walk.
  vint pending, active;
  int lane_cx[VW], lane_cy[VW], lane_cz[VW];
  int range_lo[32], range_hi[32];
  int ranges, next_range;
} Cand;

// Grid cell of a coordinate (m); build and walk compute it with the same float operations.
inline int cell_of(float v, float inv_cell) { return (int)floor(v * inv_cell); }
inline vint cell_of_v(vfloat v, float inv_cell) {
#if VW == 1
  return (int)floor(v * inv_cell);
#else
  return GT_CAT(convert_int, VW)(floor(v * inv_cell));
#endif
}

// Table slot of a cell. A row of cells along x occupies consecutive slots: the three cells of
// a stencil row are one slot interval and their points one contiguous range. Dense: rows in
// y-then-z order, so the rows a query walks are also near each other in memory. Hashed: the
// row starts at a 32-bit mix of (y, z) (murmur3's finaliser), unrelated rows land far apart,
// and a cloud spanning kilometres needs no more slots than points.
inline uint cell_slot(const Grid* g, int cx, int cy, int cz) {
  if (g->slot_mask == 0u) {
    return (uint)(cx - g->x0) +
           (uint)g->nx * ((uint)(cy - g->y0) + (uint)g->ny * (uint)(cz - g->z0));
  }
  uint h = (uint)cy * 0x9E3779B1u ^ (uint)cz * 0xC2B2AE3Du;
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return (h + (uint)cx) & g->slot_mask;
}

// Bound on the image-plane offset of a neighbour, in units of focal length. For a neighbour
// q = p + d with |d| <= r, the pixel offset is (du, dv) = (fx m_x, fy m_y) / (p_z q_z) with
// m = (p_z d_x - p_x d_z, p_z d_y - p_y d_z), and |m| <= |d| |p| (the largest singular value
// of d -> m is |p|), so (du / fx)^2 + (dv / fy)^2 <= (r |p| / (p_z (p_z - r)))^2: an ellipse of
// pixels around the query. Infinite when the point is closer to the sensor than r (then the
// whole image qualifies).
inline vfloat window_radius(V3 p, float r) {
  const vfloat bound = r * sqrt(p.x * p.x + p.y * p.y + p.z * p.z) / (p.z * (p.z - r));
  return SEL((vfloat)(INFINITY), bound, p.z > r);
}

// The queries of work-item g: organized, ceil(width / VW) work-items per row.
inline Queries queries_of(const Search* s, bool organized, __global const float* xs,
                          __global const float* ys, __global const float* zs, int g) {
  Queries Q;
  if (organized) {
    const int per_row = (s->width + VW - 1) / VW;
    const int row = g / per_row, c0 = (g - row * per_row) * VW;
    Q.first = row * s->width + c0;
    Q.lanes = min(VW, s->width - c0);
  } else {
    Q.first = g * VW;
    Q.lanes = min(VW, s->count - Q.first);
  }
  Q.p = v3(VLOAD(xs + Q.first), VLOAD(ys + Q.first), VLOAD(zs + Q.first));
  Q.ok = (LANES < Q.lanes) & isfinite(Q.p.x) & isfinite(Q.p.y) & isfinite(Q.p.z);
  return Q;
}

inline Cand cand_begin(const Search* s, bool organized, const Queries* Q) {
  Cand it;
  it.ok = Q->ok;
  it.lo = it.hi = 0;
  if (organized) {
    // One ellipse for all lanes (the largest), centred on each lane's own pixel; the 1e-3
    // margins cover the error of the estimated focal lengths, twice the slack a query and a
    // candidate sitting off their pixels (see host/src/core/frame_intrinsics.hpp).
    const float rad = hmax_float(SEL((vfloat)(0.0f), window_radius(Q->p, s->radius), Q->ok));
    it.rx = s->fx * rad * 1.001f + 1e-3f + 2.0f * s->slack;
    it.ry = s->fy * rad * 1.001f + 1e-3f + 2.0f * s->slack;
    // An ellipse larger than the image (or a point nearer than r): the whole image.
    it.full = !(it.rx < (float)s->width && it.ry < (float)s->height);
    const int hy = it.full ? s->height : (int)ceil(it.ry);
    it.row_q = Q->first / s->width;
    it.c0 = Q->first - it.row_q * s->width;
    it.row = max(it.row_q - hy, 0) - 1;
    it.row_last = ANY(Q->ok) ? min(it.row_q + hy, s->height - 1) : -1;
  } else {
    VSTORE(cell_of_v(Q->p.x, s->grid.inv_cell), it.lane_cx);
    VSTORE(cell_of_v(Q->p.y, s->grid.inv_cell), it.lane_cy);
    VSTORE(cell_of_v(Q->p.z, s->grid.inv_cell), it.lane_cz);
    it.pending = Q->ok;
    it.ranges = it.next_range = 0;
  }
  return it;
}

// Advances to the next non-empty candidate range; false when the walk is done.
inline bool cand_range(const Search* s, bool organized, Cand* it) {
  if (organized) {
    while (++it->row <= it->row_last) {
      // The ellipse's half-width at this row, cut to offsets that put at least one lane's
      // candidate inside the image row.
      const float dv = (float)(it->row - it->row_q) / it->ry;
      const int hw = it->full ? s->width : (int)ceil(it->rx * sqrt(fmax(0.0f, 1.0f - dv * dv)));
      const int t_first = max(-hw, -it->c0 - (VW - 1));
      const int t_last = min(hw, s->width - 1 - it->c0);
      if (t_first > t_last) continue;
      it->edge = t_first < -it->c0 || t_last + VW > s->width - it->c0;
      const int base = it->row * s->width + it->c0;
      it->lo = base + t_first;
      it->hi = base + t_last + 1;
      return true;
    }
    return false;
  }
  for (;;) {
    if (it->next_range < it->ranges) {
      it->lo = it->range_lo[it->next_range];
      it->hi = it->range_hi[it->next_range];
      ++it->next_range;
      return true;
    }
    if (!ANY(it->pending)) return false;
#if VW == 1
    const vint lx = it->lane_cx[0], ly = it->lane_cy[0], lz = it->lane_cz[0];
#else
    const vint lx = GT_CAT(vload, VW)(0, it->lane_cx);
    const vint ly = GT_CAT(vload, VW)(0, it->lane_cy);
    const vint lz = GT_CAT(vload, VW)(0, it->lane_cz);
#endif
    // The box of cells whose stencils are walked next. When the lanes not walked yet lie in
    // at most 2 x 2 x 2 cells, one walk over the union of their stencils serves them all (each
    // lane keeps only points within r, and every point of its own stencil is in the union);
    // otherwise the lanes in the first pending lane's cell go first.
    const vint high = (vint)(INT_MAX), low = (vint)(INT_MIN);
    int x0 = hmin_int(SEL(high, lx, it->pending)), x1 = hmax_int(SEL(low, lx, it->pending));
    int y0 = hmin_int(SEL(high, ly, it->pending)), y1 = hmax_int(SEL(low, ly, it->pending));
    int z0 = hmin_int(SEL(high, lz, it->pending)), z1 = hmax_int(SEL(low, lz, it->pending));
    if (x1 - x0 <= 1 && y1 - y0 <= 1 && z1 - z0 <= 1) {
      it->active = it->pending;
    } else {
      int pending[VW];
      VSTORE(it->pending, pending);
      int lead = 0;
      while (pending[lead] == 0) ++lead;
      x0 = x1 = it->lane_cx[lead];
      y0 = y1 = it->lane_cy[lead];
      z0 = z1 = it->lane_cz[lead];
      it->active = it->pending & (lx == x0) & (ly == y0) & (lz == z0);
    }
    it->pending = it->pending & NOT(it->active);
    // The stencil as slot intervals, one per row of cells along x, split where it wraps
    // around a hash table (a dense box never wraps: it has a margin of one cell), sorted and
    // merged so that every slot is walked once even when rows share slots.
    const uint table = s->grid.slot_mask + 1u;
    const uint row_len = (uint)(x1 - x0 + 3);
    uint lo[32], hi[32];
    int n = 0;
    for (int cz = z0 - 1; cz <= z1 + 1; ++cz) {
      for (int cy = y0 - 1; cy <= y1 + 1; ++cy) {
        const uint first = cell_slot(&s->grid, x0 - 1, cy, cz);
        if (s->grid.slot_mask == 0u || first + row_len <= table) {
          lo[n] = first;
          hi[n++] = first + row_len;
        } else {
          lo[n] = first;
          hi[n++] = table;
          lo[n] = 0u;
          hi[n++] = first + row_len - table;
        }
      }
    }
    for (int i = 1; i < n; ++i) {
      const uint l = lo[i], h = hi[i];
      int j = i - 1;
      while (j >= 0 && lo[j] > l) {
        lo[j + 1] = lo[j];
        hi[j + 1] = hi[j];
        --j;
      }
      lo[j + 1] = l;
      hi[j + 1] = h;
    }
    it->ranges = it->next_range = 0;
    uint cur_lo = lo[0], cur_hi = hi[0];
    for (int i = 1; i <= n; ++i) {
      if (i < n && lo[i] <= cur_hi) {
        cur_hi = max(cur_hi, hi[i]);
        continue;
      }
      const int a = (int)s->slot_start[cur_lo], b = (int)s->slot_start[cur_hi];
      if (a < b) {
        it->range_lo[it->ranges] = a;
        it->range_hi[it->ranges++] = b;
      }
      if (i < n) {
        cur_lo = lo[i];
        cur_hi = hi[i];
      }
    }
  }
}

// Lanes candidate k may count for (before the distance test).
inline vint cand_mask(const Search* s, bool organized, const Cand* it, int k) {
  if (!organized) return it->active;
  if (!it->edge) return it->ok;
  const vint col = (vint)(k - it->row * s->width) + LANES;
  return it->ok & (col >= 0) & (col < s->width);
}

// Candidate k's value of a search-order array, per lane.
inline vfloat cand_load(bool organized, __global const float* a, int k) {
  return organized ? VLOAD(a + k) : (vfloat)(a[k]);
}

// Lanes whose candidate k is the query point itself.
inline vint cand_is_self(bool organized, int k, const Queries* Q) {
  if (organized) return (vint)(k == Q->first ? -1 : 0);
  return (vint)(k) == (vint)(Q->first) + LANES;
}

// Runs the next statement for every candidate index k (see Cand).
#define FOR_EACH_CANDIDATE(s, organized, it, k) \
  while (cand_range((s), (organized), &(it)))   \
    for (int k = (it).lo; k < (it).hi; ++k)

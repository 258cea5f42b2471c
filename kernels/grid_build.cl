// Builds the hashed uniform grid of an unorganized cloud: the valid points sorted by grid slot
// and, within a slot, by input index, so that the result (and every sum over it) is
// deterministic. Two stable counting-sort passes keep the scattered writes inside the cache
// however large the cloud: grid_partition groups the points into up to a thousand buckets of
// consecutive slots (each chunk of input appends to every bucket as a stream), then
// grid_bucket_sort sorts each bucket, a range that fits in the cache, by slot.
// No local memory, no atomics and no work-group size assumptions: each work-item owns whole
// chunks or buckets. Point arrays in input and sorted order carry PAD elements before point 0.

// Bounding box of the valid points, per chunk of `chunk` points: partial[6 g ..] = min x, y,
// z, max x, y, z (+-inf for a chunk without valid points); the host combines the chunks.
__kernel void bounds(__global const float* xs, __global const float* ys, __global const float* zs,
                     int n, int chunk, __global float* partial) {
  const int g = get_global_id(0);
  const int begin = g * chunk;
  if (begin >= n) return;
  float3 lo = (float3)(INFINITY), hi = (float3)(-INFINITY);
  for (int k = begin; k < min(begin + chunk, n); ++k) {
    const float3 p = (float3)(xs[PAD + k], ys[PAD + k], zs[PAD + k]);
    if (isfinite(p.x) && isfinite(p.y) && isfinite(p.z)) {
      lo = fmin(lo, p);
      hi = fmax(hi, p);
    }
  }
  vstore3(lo, 2 * g, partial);
  vstore3(hi, 2 * g + 1, partial);
}

// Slot of a point (UINT_MAX: not a valid point).
inline uint point_slot(const Grid* g, float x, float y, float z) {
  if (!(isfinite(x) && isfinite(y) && isfinite(z))) return UINT_MAX;
  return cell_slot(g, cell_of(x, g->inv_cell), cell_of(y, g->inv_cell), cell_of(z, g->inv_cell));
}

// Per chunk c of `chunk` input points, the valid points of each bucket (slots s with
// s >> bucket_shift == b): counts[c * buckets + b], a chunk's row contiguous.
__kernel void grid_partition_count(__global const float* xs, __global const float* ys,
                                   __global const float* zs, int n, int chunk, GRID_PARAMS,
                                   int bucket_shift, int buckets, __global uint* counts) {
  const Grid g = GRID_FROM_PARAMS;
  const int c = get_global_id(0);
  const int begin = c * chunk;
  if (begin >= n) return;
  __global uint* row = counts + (size_t)c * buckets;
  for (int b = 0; b < buckets; ++b) row[b] = 0;
  for (int i = begin; i < min(begin + chunk, n); ++i) {
    const uint slot = point_slot(&g, xs[PAD + i], ys[PAD + i], zs[PAD + i]);
    if (slot != UINT_MAX) ++row[slot >> bucket_shift];
  }
}

// Per bucket b, over the chunks' rows: counts[c * buckets + b] becomes the bucket's points
// in the chunks before c, and totals[b] the bucket's size.
__kernel void partition_offsets(__global uint* counts, int chunks, int buckets,
                                __global uint* totals) {
  const int b = get_global_id(0);
  if (b >= buckets) return;
  uint s = 0;
  for (int c = 0; c < chunks; ++c) {
    const uint v = counts[(size_t)c * buckets + b];
    counts[(size_t)c * buckets + b] = s;
    s += v;
  }
  totals[b] = s;
}

// Sum of each chunk of `chunk` elements of in[0, n).
__kernel void scan_chunk_sums(__global const uint* in, int n, int chunk, __global uint* sums) {
  const int g = get_global_id(0);
  const int begin = g * chunk;
  if (begin >= n) return;
  const int end = min(begin + chunk, n);
  uint s = 0;
  for (int k = begin; k < end; ++k) s += in[k];
  sums[g] = s;
}

// Exclusive scan of in[0, n) into out[0, n], out[n] = total, by one work-item: the top level
// of the scan, a few hundred elements at most.
__kernel void scan_serial(__global const uint* in, int n, __global uint* out) {
  if (get_global_id(0) != 0) return;
  uint s = 0;
  for (int k = 0; k < n; ++k) {
    const uint v = in[k];
    out[k] = s;
    s += v;
  }
  out[n] = s;
}

// Exclusive scan of each chunk, offset by the scanned chunk sums; the last chunk also writes
// the total to out[n].
__kernel void scan_chunk_apply(__global const uint* in, int n, int chunk,
                               __global const uint* chunk_offsets, __global uint* out) {
  const int g = get_global_id(0);
  const int begin = g * chunk;
  if (begin >= n) return;
  const int end = min(begin + chunk, n);
  uint s = chunk_offsets[g];
  for (int k = begin; k < end; ++k) {
    const uint v = in[k];
    out[k] = s;
    s += v;
  }
  if (end == n) out[n] = s;
}

// Appends each chunk's valid points, in input order, to their buckets: partitioned[t] = (x, y,
// z, input index bits). bucket_start: the scanned bucket sizes; offsets: partition_offsets's,
// advanced as the chunk's points are placed.
__kernel void grid_partition(__global const float* xs, __global const float* ys,
                             __global const float* zs, int n, int chunk, GRID_PARAMS,
                             int bucket_shift, int buckets, __global const uint* bucket_start,
                             __global uint* offsets, __global float4* partitioned) {
  const Grid g = GRID_FROM_PARAMS;
  const int c = get_global_id(0);
  const int begin = c * chunk;
  if (begin >= n) return;
  __global uint* row = offsets + (size_t)c * buckets;
  for (int i = begin; i < min(begin + chunk, n); ++i) {
    const float x = xs[PAD + i], y = ys[PAD + i], z = zs[PAD + i];
    const uint slot = point_slot(&g, x, y, z);
    if (slot == UINT_MAX) continue;
    const uint b = slot >> bucket_shift;
    partitioned[bucket_start[b] + row[b]++] = (float4)(x, y, z, as_float(i));
  }
}

// Counting sort of each bucket by slot, stable, so each slot's points stay in input order:
// writes the bucket's slot_start entries (the last bucket also slot_start[table_size]), the
// sorted points and order[k] = input index of sorted point k. Scratch: slot_fill, one per slot,
// and partitioned_slot, one per point.
__kernel void grid_bucket_sort(__global const float4* partitioned,
                               __global const uint* bucket_start, GRID_PARAMS, int bucket_shift,
                               int buckets, int table_size, __global uint* slot_fill,
                               __global uint* partitioned_slot, __global uint* slot_start,
                               __global float* sorted_x, __global float* sorted_y,
                               __global float* sorted_z, __global int* order) {
  const Grid g = GRID_FROM_PARAMS;
  const int b = get_global_id(0);
  if (b >= buckets) return;
  const int s_begin = b << bucket_shift;
  const int s_end = min((b + 1) << bucket_shift, table_size);
  const uint t_begin = bucket_start[b], t_end = bucket_start[b + 1];
  for (int s = s_begin; s < s_end; ++s) slot_fill[s] = 0;
  for (uint t = t_begin; t < t_end; ++t) {
    const float4 p = partitioned[t];
    const uint slot = point_slot(&g, p.x, p.y, p.z);
    partitioned_slot[t] = slot;
    ++slot_fill[slot];
  }
  uint k = t_begin;
  for (int s = s_begin; s < s_end; ++s) {
    const uint size = slot_fill[s];
    slot_start[s] = k;
    slot_fill[s] = k;
    k += size;
  }
  if (b == buckets - 1) slot_start[table_size] = k;
  for (uint t = t_begin; t < t_end; ++t) {
    const float4 p = partitioned[t];
    const uint at = slot_fill[partitioned_slot[t]]++;
    sorted_x[PAD + at] = p.x;
    sorted_y[PAD + at] = p.y;
    sorted_z[PAD + at] = p.z;
    order[at] = as_int(p.w);
  }
}

// dst[k] = src[order[k]] for the sorted positions k < count (three arrays at once).
__kernel void gather3(__global const float* src_x, __global const float* src_y,
                      __global const float* src_z, __global const int* order, int count,
                      __global float* dst_x, __global float* dst_y, __global float* dst_z) {
  const int k = get_global_id(0);
  if (k >= count) return;
  const int i = PAD + order[k];
  dst_x[PAD + k] = src_x[i];
  dst_y[PAD + k] = src_y[i];
  dst_z[PAD + k] = src_z[i];
}

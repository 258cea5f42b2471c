// Builds the hashed uniform grid of an unorganized cloud by counting sort: count the points
// of each slot, scan the counts into slot starts, scatter the points into slot order, then sort
// each slot by input index so that the result (and every sum over it) is deterministic.
// No local memory and no work-group size assumptions: each work-item owns whole chunks.
// Point arrays (input and sorted order alike) carry PAD elements before point 0.

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

// Counts the valid points of each slot; point_slot[i] = slot of point i (UINT_MAX: invalid).
__kernel void grid_count(__global const float* xs, __global const float* ys,
                         __global const float* zs, int n, GRID_PARAMS,
                         __global volatile uint* counts, __global uint* point_slot) {
  const Grid g = GRID_FROM_PARAMS;
  const int i = get_global_id(0);
  if (i >= n) return;
  const float x = xs[PAD + i], y = ys[PAD + i], z = zs[PAD + i];
  if (!(isfinite(x) && isfinite(y) && isfinite(z))) {
    point_slot[i] = UINT_MAX;
    return;
  }
  const uint slot = cell_slot(&g, cell_of(x, inv_cell), cell_of(y, inv_cell), cell_of(z, inv_cell));
  point_slot[i] = slot;
  atomic_inc(&counts[slot]);
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

// Puts each valid point into its slot's range (in arbitrary order within the slot).
__kernel void grid_scatter(__global const float* xs, __global const float* ys,
                           __global const float* zs, int n, __global const uint* point_slot,
                           __global const uint* slot_start, __global volatile uint* fill,
                           __global float* sorted_x, __global float* sorted_y,
                           __global float* sorted_z, __global int* order) {
  const int i = get_global_id(0);
  if (i >= n) return;
  const uint slot = point_slot[i];
  if (slot == UINT_MAX) return;
  const uint k = slot_start[slot] + atomic_inc(&fill[slot]);
  sorted_x[PAD + k] = xs[PAD + i];
  sorted_y[PAD + k] = ys[PAD + i];
  sorted_z[PAD + k] = zs[PAD + i];
  order[k] = i;
}

// Sorts each slot's range by input index (insertion sort: slots hold tens of points).
__kernel void grid_sort_slots(__global const uint* slot_start, int table_size,
                              __global float* sorted_x, __global float* sorted_y,
                              __global float* sorted_z, __global int* order) {
  const int s = get_global_id(0);
  if (s >= table_size) return;
  sorted_x += PAD;
  sorted_y += PAD;
  sorted_z += PAD;
  const int begin = (int)slot_start[s], end = (int)slot_start[s + 1];
  for (int k = begin + 1; k < end; ++k) {
    const int key = order[k];
    const float x = sorted_x[k], y = sorted_y[k], z = sorted_z[k];
    int j = k - 1;
    while (j >= begin && order[j] > key) {
      order[j + 1] = order[j];
      sorted_x[j + 1] = sorted_x[j];
      sorted_y[j + 1] = sorted_y[j];
      sorted_z[j + 1] = sorted_z[j];
      --j;
    }
    order[j + 1] = key;
    sorted_x[j + 1] = x;
    sorted_y[j + 1] = y;
    sorted_z[j + 1] = z;
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

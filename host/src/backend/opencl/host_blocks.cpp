#include "host_blocks.hpp"

#include <cstdlib>
#include <map>
#include <mutex>
#include <new>

namespace groovetrace::ocl {
namespace {

constexpr std::size_t kPage = 4096;
constexpr std::size_t kKeptMax = std::size_t{2} << 30;

std::mutex g_mutex;
std::multimap<std::size_t, void*> g_kept;  // capacity -> block
std::size_t g_kept_bytes = 0;

}  // namespace

void* take_host_block(std::size_t bytes, std::size_t* capacity) {
  const std::size_t want = (bytes + kPage - 1) / kPage * kPage;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    // The smallest kept block that fits, unless it wastes more than an eighth.
    auto it = g_kept.lower_bound(want);
    if (it != g_kept.end() && it->first <= want + want / 8) {
      void* block = it->second;
      *capacity = it->first;
      g_kept_bytes -= it->first;
      g_kept.erase(it);
      return block;
    }
  }
  void* block = std::aligned_alloc(kPage, want);
  if (block == nullptr) throw std::bad_alloc();
  *capacity = want;
  return block;
}

void give_host_block(void* block, std::size_t capacity) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (g_kept_bytes + capacity <= kKeptMax) {
      g_kept.emplace(capacity, block);
      g_kept_bytes += capacity;
      return;
    }
  }
  std::free(block);
}

}  // namespace groovetrace::ocl

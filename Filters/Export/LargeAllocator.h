/**
 * @file LargeAllocator.h
 * @brief An allocator for the large arrays of a grid (tens to hundreds of MB) that leaves
 * new elements default-initialized: resize() does not zero-fill memory that is written
 * right after (the mesher's node arrays, point numbers). On virtual machines touching
 * memory costs more than the arithmetic, so each array is touched once, by its writer.
 * (Transparent huge pages were tried: their zeroing made a run after another large writer
 * slower, not faster.)
 */
#pragma once

#include <memory>
#include <utility>
#include <vector>

namespace blockforge
{
namespace exporting
{
template <typename T>
struct LargeAllocator : std::allocator<T>
{
  using value_type = T;
  template <typename U>
  struct rebind
  {
    using other = LargeAllocator<U>;
  };
  LargeAllocator() noexcept = default;
  template <typename U>
  LargeAllocator(const LargeAllocator<U>&) noexcept
  {
  }
  /// Default-initialize: resize() leaves the values to be written.
  template <typename U>
  void construct(U* pointer) noexcept
  {
    ::new (static_cast<void*>(pointer)) U;
  }
  template <typename U, typename... Args>
  void construct(U* pointer, Args&&... args)
  {
    ::new (static_cast<void*>(pointer)) U(std::forward<Args>(args)...);
  }
};

/// A vector for large grid arrays.
template <typename T>
using LargeVector = std::vector<T, LargeAllocator<T>>;
} // namespace exporting
} // namespace blockforge

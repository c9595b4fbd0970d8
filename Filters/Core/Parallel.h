/**
 * @file Parallel.h
 * @brief How the numerical core runs independent chunks of work: one after the other by
 * default, or on threads once the layer above installs a runner (the VTK module installs
 * vtkSMPTools, see BlockForgeThreads.h). The core stays free of any threading library.
 *
 * Every caller splits its work so that the result does not depend on the chunking or the
 * order of the chunks: grids and quality measures are the same bit for bit on any number
 * of threads.
 */
#pragma once

#include <functional>

namespace blockforge
{
/// Calls body(begin, end) for every chunk index range of [0, count), possibly concurrently.
using ChunkRunner = std::function<void(long count, const std::function<void(long, long)>& body)>;

/// Installs the runner and the number of threads it uses (`threads` >= 1). An empty runner
/// restores the sequential default. `grainScale` scales the smallest work worth a chunk
/// (tests use a small one to split small grids).
void setChunkRunner(ChunkRunner runner, int threads, double grainScale = 1.0);

/// Threads of the installed runner (1 for the sequential default).
int chunkThreads();

/// How many chunks to split `items` units of work into: 1 without threads, else up to
/// 4 per thread with at least `minimumItems` (times the grain scale) each, at most
/// `maximumChunks`.
long chunkCount(long items, long minimumItems, long maximumChunks);

/**
 * Runs body(chunk) for chunk = 0 .. count-1 with the installed runner. Chunks must write
 * disjoint memory. Exceptions thrown by a chunk are rethrown here (the first one in chunk
 * order, so the message does not depend on the threads).
 */
void forEachChunk(long count, const std::function<void(long chunk)>& body);
} // namespace blockforge

/**
 * @file Transfinite.h
 * @brief Discrete transfinite interpolation of faces (2-D Coons, paper eq. 3) and blocks
 * (trilinear TFI from 6 faces, 12 edges and 8 vertices, paper eq. 6).
 *
 * Node arrays are interleaved xyz doubles. Structured ordering is VTK's: i fastest,
 * then j, then k. Boundary nodes are copied bit for bit from the given edges/faces, so
 * two blocks built from the same face grid share identical coordinates there.
 *
 * Local block notation (paper Fig. 7, 0-based here): vertices V0..V7 in VTK hexahedron
 * order ((s,t,u) = (0,0,0),(1,0,0),(1,1,0),(0,1,0),(0,0,1),(1,0,1),(1,1,1),(0,1,1)),
 * i runs along s, j along t, k along u.
 * Edges (paper E1..E12 -> index 0..11), each directed along increasing s, t or u:
 *   0: V0->V1 (t=0,u=0)   1: V1->V2 (s=1,u=0)   2: V3->V2 (t=1,u=0)   3: V0->V3 (s=0,u=0)
 *   4: V4->V5 (t=0,u=1)   5: V5->V6 (s=1,u=1)   6: V7->V6 (t=1,u=1)   7: V4->V7 (s=0,u=1)
 *   8: V0->V4 (s=0,t=0)   9: V1->V5 (s=1,t=0)  10: V2->V6 (s=1,t=1)  11: V3->V7 (s=0,t=1)
 * Faces (paper S1..S6 -> index 0..5), each a grid in the block's own index order:
 *   0: s=0 (j,k) j fastest   1: s=1 (j,k)
 *   2: t=0 (i,k) i fastest   3: t=1 (i,k)
 *   4: u=0 (i,j) i fastest   5: u=1 (i,j)
 */
#pragma once

#include "Types.h"

#include <array>

namespace blockforge
{
/**
 * How the interior blends its boundary. Linear: the weights are the node parameters
 * (paper eqs. 3 and 6), so an interior grid line takes the fractions of the edges beside it:
 * where it is shorter or longer than their blend, its end cells are too. EndCells: the
 * weights are the parameters' smoothstep x^2 (3 - 2x), flat at both ends, so an interior
 * line's end cells are the blend of the edges' end cells as lengths (the difference in
 * length goes to its middle cells): two blocks whose edges end in matched cells keep
 * matching cells across their interface all along it. Both interpolate the boundary
 * exactly. Each direction has its own (s, t, u; a face's two).
 */
enum class Blending
{
  Linear,
  EndCells,
  /// Linear where every interior line of that direction on the boundary (a face's own
  /// lines after a linear pass; a block's on its four faces along it) is within
  /// kAdaptiveTolerance of the blend of the two edges beside it in length, so that linear
  /// fractions already keep its end cells within that; else the weights x + b x (1 - x)
  /// (2x - 1), b = 1 - kAdaptiveTolerance / spread (b = 1: EndCells), just so far towards
  /// EndCells that the end cells stay within kAdaptiveTolerance of the edges'. An inlet
  /// block in front of a round nose whose middle lines are half as long as its sides
  /// (axial_passage_oh's U_M on the turbine) then keeps the O-grid's outer cell there,
  /// while a block whose lines are alike is the linear grid bit for bit.
  Adaptive,
  /// Linear, and on a face (transfiniteFace) the first and last cells of the lines of that
  /// direction keep most of the width of their ends' cells: where a line's cell at a side
  /// edge comes out narrower than 0.7 times the blend (along that side) of the side's two end
  /// cells, every line's node next to that side whose cell is under (1 - kAdaptiveTolerance)
  /// of the blend moves along its cell until the cell is that wide, and the line's other
  /// interior nodes follow by a share falling linearly to the node next to the far side. Why: the linear blend of a first cell pointing across the side (an
  /// inlet's) and one leaving nearly along it (an O arc leaving a fan corner) is shortest
  /// mid-way (axial_passage_oh's U_M on the compressor: 0.47 of its ends against U_L's cells).
  /// A face whose cells keep their width is the linear grid bit for bit; a block's interior
  /// (transfiniteBlock) is linear, so it carries its faces' correction.
  EndWidths
};

/// Relative length spread of interior lines up to which Blending::Adaptive stays linear.
constexpr double kAdaptiveTolerance = 0.2;

/// Nodes of one edge and their relative positions (distribution parameters) in [0, 1].
struct EdgeNodes
{
  const double* xyz = nullptr;    ///< count * 3 coordinates
  const double* params = nullptr; ///< count parameters, 0 first, 1 last
  int count = 0;
};

/**
 * 2-D TFI of a face grid of ni x nj nodes (i fastest) from its four edges:
 * bottom (j = 0) and top (j = nj-1) with ni nodes in increasing i, left (i = 0) and
 * right (i = ni-1) with nj nodes in increasing j. Edge parameters may differ on opposite
 * edges; the interior (s, t) of each node is the intersection of the lines joining
 * matching parameters, which makes the interpolation exact on every edge. `out` holds
 * ni * nj * 3 doubles.
 */
void transfiniteFace(const EdgeNodes& bottom, const EdgeNodes& top, const EdgeNodes& left,
  const EdgeNodes& right, double* out,
  std::array<Blending, 2> blending = { Blending::Linear, Blending::Linear });

/// Boundary of one block in its local orientation (see the file comment).
struct BlockBoundary
{
  std::array<const double*, 6> faces{};    ///< face grids, interleaved xyz
  std::array<const double*, 12> edgeParams{}; ///< distribution parameters of each edge
  std::array<Blending, 3> blending{ Blending::Linear, Blending::Linear, Blending::Linear };
};

/**
 * 3-D TFI (paper eq. 6) of a block with ni x nj x nk nodes. Boundary nodes come from
 * the faces (bit-identical copies); interior nodes blend the 6 faces, 12 edges (read
 * from the faces) and 8 vertices. When the four parallel edges in a direction share the
 * same parameters the interpolation variables are separable and the loop is the fast
 * path; otherwise (s, t, u) of each node solve the coupled bilinear blends of the edge
 * parameters (a few Gauss-Seidel sweeps from the edge averages, see Transfinite.cpp).
 * Degenerate blocks (collapsed edges or faces) need no special treatment. Where faces
 * share nodes (block edges and vertices), faces 4/5 are copied over 2/3 and those over
 * 0/1; faces built from the same edge arrays agree there bit for bit anyway.
 * `out` holds ni * nj * nk * 3 doubles.
 */
void transfiniteBlock(const BlockBoundary& boundary, int ni, int nj, int nk, double* out);
} // namespace blockforge

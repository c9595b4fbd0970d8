/**
 * @file Distribution.h
 * @brief Node distribution laws along a block edge (paper eq. 7 and the laws CFD
 * engineers expect): each returns exactly the requested node count, 0 and 1 exactly at
 * the ends, strictly increasing in between.
 */
#pragma once

#include "Types.h"

namespace blockforge
{
/**
 * @brief A distribution law along an edge, from its start vertex to its end vertex.
 */
struct DistributionLaw
{
  enum class Kind
  {
    Uniform,   ///< equal cells
    Geometric, ///< paper eq. 7: each cell is ExpansionRatio times the previous one
    TwoSided,  ///< cells grow by ExpansionRatio from both ends towards the middle
    FirstCell, ///< first cell of FirstCellSize, growing by at most ExpansionRatio
    Ends,      ///< first and last cells FirstCellSize and LastCellSize times the mean cell
    Match,     ///< first and last cells of given lengths (FirstCellSize, LastCellSize; 0:
               ///< free), cells growing from both ends by ExpansionRatio up to a uniform
               ///< middle; the mesher sets the end lengths to those of the cells continuing
               ///< the edge across block interfaces
    ProjectFrom ///< the nodes are the closest points on this edge of the nodes of another
                ///< edge (SourceEdge, an index the model layer gives meaning to): on a curve
                ///< offset from that edge's, the normal offsets of its nodes. Placed by the
                ///< mesher; distributeNodes has no nodes for it.
  };
  Kind kind = Kind::Uniform;
  /// Geometric/TwoSided: ratio of successive cell sizes (k in eq. 7, > 0).
  /// Match: the ratio the cells grow by from each end (> 1); larger only when the edge
  /// has too few cells to reach its length that way.
  /// FirstCell: the largest allowed ratio (> 1); cells grow geometrically from
  /// FirstCellSize and stay constant once large enough to fill the edge. 0 for
  /// FirstCell means "solve the ratio so that all cells grow geometrically".
  double expansionRatio = 1.0;
  /// FirstCell: size of the first cell in length units of the edge (> 0).
  /// Ends: size of the first cell over the mean cell (edge length / cells, > 0).
  /// Match: length of the first cell (0: free).
  double firstCellSize = 0.0;
  /// Ends: size of the last cell over the mean cell (> 0). Relative sizes do not change
  /// with the cell count, so a refined grid keeps the shape: neighbour blocks whose end
  /// cells match at one density match at all.
  /// Match: length of the last cell (0: free).
  double lastCellSize = 0.0;
  /// ProjectFrom: the edge whose nodes are projected (the model's named edge index).
  int sourceEdge = -1;
  /// Match only: the largest angle [rad] between an end cell (the chord from the end to
  /// the next node) and the edge's chord from end to end; 0: none. A curved edge leaving
  /// its end across its course (a blade side leaving a round leading edge across the
  /// pitch) gets its end cell lengthened until it leans no more, and the edges continuing
  /// it across the interface take that cell too (Filters/Model/MatchedEdges.cpp).
  double leanLimit = 0.0;
  /// ProjectFrom only: where the first (last) vertex of the edge is not the projection of
  /// the source edge's end vertex (an O-grid corner off the normal of its foot on the
  /// blade), the projected nodes near that end move along the edge towards it, by the
  /// whole distance at the end and by less farther in (a smoothstep in the edge's arc
  /// length over fadeStart (fadeEnd) times that distance), so the end cell keeps the
  /// projected length and no cell grows by more than 1 + 1.5 / fade; 0: that end vertex as
  /// it is (the end cell takes up the difference).
  double fadeStart = 0.0;
  double fadeEnd = 0.0;
  /// Ends only: the flatness k (>= 1) of the bump that fills the edge, 1 - |2 xi - 1|^(2k)
  /// (k = 1: 4 xi (1 - xi), the default). A flatter bump keeps the middle cells nearer the
  /// mean when the end cells are small (ends 0.1 on 16 cells: the largest cell 1.51 times
  /// the mean with k = 2, 2.09 with k = 1), the cells growing faster next to the ends.
  double endsFlatness = 1.0;
  /// Match only: 0 (the default), cells grow from the matched end cells by
  /// expansionRatio up to a uniform middle; k >= 1, the cells between the matched end
  /// cells follow the Ends law's shape with them (relative to the mean cell) and a bump of
  /// flatness k, so that the edge keeps the fractions of an `ends`-graded edge beside it
  /// (axial_passage_oh: an O-grid side starting from the O corner's small cell, beside a
  /// periodic line graded `ends`: grown by 2 the sides' middle cells were 2.7 times the
  /// mean at density 0.5, chords far off the turbine's curved O-grid side).
  double matchFlatness = 0.0;
  /// Match only: 0 (the default), no limit; k > 0, the matched end cells of this edge at
  /// most k times its mean cell (length over cells), the edges continuing it taking the
  /// lowered cell too: a narrow edge whose group holds only matched edges, some of them
  /// much wider, would otherwise start from cells above its mean and shrink to a fraction
  /// of it in its middle (axial_passage_oh's wake block at a sharp trailing edge: outlet
  /// cells of 0.08 mm between end cells of 1 mm, mean 0.39 mm, that fail checkMesh's face
  /// tets).
  double matchAtMost = 0.0;

  bool operator==(const DistributionLaw& o) const
  {
    return kind == o.kind && expansionRatio == o.expansionRatio &&
      firstCellSize == o.firstCellSize && lastCellSize == o.lastCellSize &&
      sourceEdge == o.sourceEdge && leanLimit == o.leanLimit && fadeStart == o.fadeStart &&
      fadeEnd == o.fadeEnd && endsFlatness == o.endsFlatness &&
      matchFlatness == o.matchFlatness && matchAtMost == o.matchAtMost;
  }
  bool operator!=(const DistributionLaw& o) const { return !(*this == o); }
};

/**
 * Relative node positions s_0 = 0 < s_1 < ... < s_(n-1) = 1 for `nodeCount` nodes
 * (>= 2) on an edge of length `edgeLength` (used only by FirstCell). Throws
 * GeometryError when the law cannot be met (non-positive ratio, first cell too large
 * or too small for the edge with the given ratio, a cell below 1e-12 of the edge, whose
 * nodes would coincide once placed; a ProjectFrom law, whose nodes come from another
 * edge), the message says why in user terms.
 */
std::vector<double> distributeNodes(const DistributionLaw& law, int nodeCount,
  double edgeLength = 1.0);

/// Default growth ratio of the Match law.
constexpr double DefaultMatchRatio = 1.2;

/**
 * Relative node positions for `nodeCount` nodes on an edge of `length` whose first and
 * last cells have the lengths `first` and `last` (0 or less: free): cells grow from each
 * given end by `ratio` (> 1) and are uniform where that would make them larger than the
 * edge needs. When the cells growing by `ratio` cannot fill the edge, the ratio is raised
 * until they do; when the given end cells are too large for the edge, the cells are as
 * near them as filling the edge allows (uniform in the limit). Both end cells above the
 * mean cell (and not kept by cells grown to a uniform middle): the Ends law's shape
 * between them, with the end cells lowered towards the mean where that shape would change
 * by more than ratio^2 from one cell to the next (few cells between large ends). With `flatness` >= 1
 * (DistributionLaw::matchFlatness) the nodes are instead the Ends law's with the given end
 * cells over the mean cell (a free end: the mean cell) and that bump flatness.
 */
std::vector<double> matchedNodes(double first, double last, double length, int nodeCount,
  double ratio, double flatness = 0.0);

/// The law seen from the other end of the edge (Geometric k -> 1/k, Ends and Match swapped). FirstCell cannot be
/// reversed into a law of the same kind; callers reverse its node parameters instead.
DistributionLaw reversedLaw(const DistributionLaw& law);
} // namespace blockforge

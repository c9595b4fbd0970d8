/**
 * @file Transfinite.cpp
 * @brief Discrete 2-D and 3-D transfinite interpolation (paper eqs. 3 and 6).
 */
#include "Transfinite.h"

#include "Parallel.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace blockforge
{
namespace
{
/// The blending weight of parameter x for a blend b from linear (0) towards end cells (1):
/// x + b x (1 - x) (2x - 1), its slope 1 - b at both ends (b = 1: smoothstep x^2 (3 - 2x)).
inline double weight(double x, double b)
{
  if (b == 0.0)
  {
    return x;
  }
  if (b == 1.0)
  {
    return x * x * (3.0 - 2.0 * x);
  }
  return x + b * x * (1.0 - x) * (2.0 * x - 1.0);
}

/// The blend b of a fixed Blending (Adaptive is resolved before: resolveAdaptive).
inline double fixedBlend(Blending blending)
{
  return blending == Blending::EndCells ? 1.0 : 0.0;
}

/// Distance between two grid nodes (3 doubles each).
inline double nodeDistance(const double* p, const double* q)
{
  return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
    (p[2] - q[2]) * (p[2] - q[2]));
}

/// Largest relative difference between the length of an interior line of a grid of
/// na x nb nodes (a fastest) and the blend of the two boundary lines beside it: lines
/// along b at each a (alongB) weighted by `across` (the parameters of a, na values), or
/// lines along a at each b.
double lineSpread(const double* grid, int na, int nb, bool alongB, const double* across)
{
  const int lines = alongB ? na : nb;
  const int nodes = alongB ? nb : na;
  const auto length = [&](int line) {
    double sum = 0.0;
    for (int n = 1; n < nodes; ++n)
    {
      const long a = alongB ? static_cast<long>(line) + static_cast<long>(na) * n
                            : static_cast<long>(n) + static_cast<long>(na) * line;
      const long b = alongB ? a - na : a - 1;
      sum += nodeDistance(grid + 3 * a, grid + 3 * b);
    }
    return sum;
  };
  const double first = length(0), last = length(lines - 1);
  double spread = 0.0;
  for (int line = 1; line < lines - 1; ++line)
  {
    const double x = across[line];
    const double blend = (1.0 - x) * first + x * last;
    if (blend > 0.0)
    {
      spread = std::max(spread, std::abs(length(line) / blend - 1.0));
    }
  }
  return spread;
}

/// The blend b of an Adaptive direction whose lines spread by `spread` (Blending).
inline double adaptiveBlend(double spread)
{
  return spread > kAdaptiveTolerance ? 1.0 - kAdaptiveTolerance / spread : 0.0;
}

/// Blending::EndWidths corrects a side's cells only where one of them is narrower than this
/// fraction of the blend of the side's end cells (then all up to 1 - kAdaptiveTolerance).
/// Why not 1 - kAdaptiveTolerance itself: axial_passage_oh's U_M / D_M come out at least
/// 0.75 of that blend on Rotor 37 and the distributor (their grids stay the same) and 0.69
/// on the turbine (some of its faces lifted a little), 0.46-0.69 beside the compressor's
/// fans (its D_M hub face, 0.74-0.93, is left).
constexpr double kEndWidthsTrigger = 0.7;

/// Blending::EndWidths on a face grid of na x nb nodes (a fastest), for the lines along a
/// (alongA) or along b: `sideParams` the parameters of the two side edges the lines run
/// between (one per line), `acrossA` / `acrossB` those of the two edges along the lines
/// (one per node of a line), whose mean places a node across the face.
void keepEndWidths(double* grid, int na, int nb, bool alongA, const double* sideParams[2],
  const double* acrossA, const double* acrossB)
{
  const int nodes = alongA ? na : nb; // along a line
  const int lines = alongA ? nb : na;
  if (nodes < 3 || lines < 3)
  {
    return;
  }
  const auto at = [&](int node, int line) -> double* {
    const long index = alongA ? node + static_cast<long>(na) * line
                              : line + static_cast<long>(na) * node;
    return grid + 3 * index;
  };
  // the displacement of each line's node next to each side, from the linear grid
  std::vector<double> shift[2];
  for (int side = 0; side < 2; ++side)
  {
    const int edgeNode = side == 0 ? 0 : nodes - 1;
    const int nextNode = side == 0 ? 1 : nodes - 2;
    const double firstWidth = nodeDistance(at(nextNode, 0), at(edgeNode, 0));
    const double lastWidth = nodeDistance(at(nextNode, lines - 1), at(edgeNode, lines - 1));
    double least = 1.0;
    for (int line = 1; line < lines - 1; ++line)
    {
      const double t = sideParams[side][line];
      const double target = (1.0 - t) * firstWidth + t * lastWidth;
      least = std::min(least, nodeDistance(at(nextNode, line), at(edgeNode, line)) / target);
    }
    if (!(least < kEndWidthsTrigger))
    {
      continue;
    }
    shift[side].assign(3 * static_cast<std::size_t>(lines), 0.0);
    for (int line = 1; line < lines - 1; ++line)
    {
      // up to (1 - kAdaptiveTolerance) of the blend: lines within that stay (bit for bit)
      const double t = sideParams[side][line];
      const double target = (1.0 - kAdaptiveTolerance) * ((1.0 - t) * firstWidth + t * lastWidth);
      const double* p = at(edgeNode, line);
      const double* q = at(nextNode, line);
      const double width = nodeDistance(q, p);
      if (!(width > 0.0) || !(target > width))
      {
        continue;
      }
      // along the cell's own direction, so that the cell is `target` wide (across the side
      // instead, the cells by a corner whose far end leaves nearly along the side were
      // sheared: the compressor's U_M corner cell at oa_f, scaled Jacobian 0.132 -> 0.089)
      const double move = target / width - 1.0;
      for (int c = 0; c < 3; ++c)
      {
        shift[side][3 * line + c] = move * (q[c] - p[c]);
      }
    }
  }
  for (int side = 0; side < 2; ++side)
  {
    if (shift[side].empty())
    {
      continue;
    }
    // the share falls linearly (in the nodes' parameters) from the node next to this side
    // to the node next to the far side, so that the far side's cells keep their width
    const auto sigma = [&](int node) { return 0.5 * (acrossA[node] + acrossB[node]); };
    const double near = sigma(side == 0 ? 1 : nodes - 2);
    const double far = sigma(side == 0 ? nodes - 2 : 1);
    for (int line = 1; line < lines - 1; ++line)
    {
      const double* move = shift[side].data() + 3 * line;
      for (int node = 1; node < nodes - 1; ++node)
      {
        const double share = far == near ? 1.0 : (far - sigma(node)) / (far - near);
        double* p = at(node, line);
        for (int c = 0; c < 3; ++c)
        {
          p[c] += share * move[c];
        }
      }
    }
  }
}

inline void copyNode(const double* from, double* to)
{
  to[0] = from[0];
  to[1] = from[1];
  to[2] = from[2];
}

void checkEdge(const EdgeNodes& edge, int expectedCount, const char* name)
{
  if (!edge.xyz || !edge.params)
  {
    throw GeometryError(std::string("transfinite face: the ") + name + " edge has no nodes");
  }
  if (edge.count != expectedCount)
  {
    throw GeometryError(std::string("transfinite face: the ") + name + " edge has " +
      std::to_string(edge.count) + " nodes where the opposite edge has " +
      std::to_string(expectedCount));
  }
}

/// True when the arrays hold the same values, so the parameter of this direction does
/// not depend on the position across the block.
bool sameParameters(const double* a, const double* b, int count)
{
  return a == b || std::equal(a, a + count, b);
}

/// Read-only view of the six face grids with the block's index conventions.
struct BlockFaces
{
  const double* f[6];
  int ni, nj;

  const double* s0(int j, int k) const { return f[0] + 3 * (j + static_cast<long>(nj) * k); }
  const double* s1(int j, int k) const { return f[1] + 3 * (j + static_cast<long>(nj) * k); }
  const double* t0(int i, int k) const { return f[2] + 3 * (i + static_cast<long>(ni) * k); }
  const double* t1(int i, int k) const { return f[3] + 3 * (i + static_cast<long>(ni) * k); }
  const double* u0(int i, int j) const { return f[4] + 3 * (i + static_cast<long>(ni) * j); }
  const double* u1(int i, int j) const { return f[5] + 3 * (i + static_cast<long>(ni) * j); }
};

/// Copies the six faces into the block. Where faces share nodes (block edges) the
/// u-faces win over the t-faces, and those over the s-faces; the interpolation reads
/// edges and vertices from the same faces so boundary and interior agree.
void copyBoundary(const BlockFaces& faces, int ni, int nj, int nk, double* out)
{
  const long plane = static_cast<long>(ni) * nj;
  std::memcpy(out, faces.f[4], sizeof(double) * 3 * plane);
  std::memcpy(out + 3 * plane * (nk - 1), faces.f[5], sizeof(double) * 3 * plane);
  for (int k = 1; k < nk - 1; ++k)
  {
    double* layer = out + 3 * plane * k;
    std::memcpy(layer, faces.t0(0, k), sizeof(double) * 3 * ni);
    std::memcpy(
      layer + 3 * static_cast<long>(ni) * (nj - 1), faces.t1(0, k), sizeof(double) * 3 * ni);
    for (int j = 1; j < nj - 1; ++j)
    {
      double* row = layer + 3 * static_cast<long>(ni) * j;
      copyNode(faces.s0(j, k), row);
      copyNode(faces.s1(j, k), row + 3 * (ni - 1));
    }
  }
}

/**
 * Interior when every direction is separable: s = s(i), t = t(j), u = u(k). Eq. 6 is
 * regrouped so that only three-term blends remain per node:
 *   P = A + s (B - A) + L(i) + t (H(i) - L(i)) + F4(i, j) + u (F5(i, j) - F4(i, j))
 *   L = F2(i, k) - [(1-u) E0(i) + u E4(i)],   H = F3(i, k) - [(1-u) E2(i) + u E6(i)]
 *   A = F0(j, k) - [(1-u) E3(j) + u E7(j)] - [(1-t) E8(k) + t E11(k)] + vertex terms of (1-s)
 *   B = F1(j, k) - [(1-u) E1(j) + u E5(j)] - [(1-t) E9(k) + t E10(k)] + vertex terms of s
 * A and B are formed once per (j, k) line, L and H once per k-layer, F5 - F4 once per
 * block; the innermost loop over i reads four contiguous rows and writes one.
 */
void interiorSeparable(const BlockFaces& F, const std::array<const double*, 12>& params, int ni,
  int nj, int nk, int kBegin, int kEnd, const double* uFaceDifference,
  const std::array<double, 3>& blending, double* out)
{
  const double* sOfI = params[0];
  const double* tOfJ = params[3];
  const double* uOfK = params[8];
  std::vector<double> sWeights, tWeights, uWeights;
  const auto weights = [](const double* p, int n, double b, std::vector<double>& w) {
    if (b == 0.0)
    {
      return p;
    }
    w.resize(n);
    for (int i = 0; i < n; ++i)
    {
      w[i] = weight(p[i], b);
    }
    return static_cast<const double*>(w.data());
  };
  sOfI = weights(params[0], ni, blending[0], sWeights);
  tOfJ = weights(params[3], nj, blending[1], tWeights);
  uOfK = weights(params[8], nk, blending[2], uWeights);

  const double* V0 = F.u0(0, 0);
  const double* V1 = F.u0(ni - 1, 0);
  const double* V2 = F.u0(ni - 1, nj - 1);
  const double* V3 = F.u0(0, nj - 1);
  const double* V4 = F.u1(0, 0);
  const double* V5 = F.u1(ni - 1, 0);
  const double* V6 = F.u1(ni - 1, nj - 1);
  const double* V7 = F.u1(0, nj - 1);

  const long plane = static_cast<long>(ni) * nj;
  std::vector<double> tBlendBase(3 * ni), tBlendSlope(3 * ni);

  for (int k = kBegin; k < kEnd; ++k)
  {
    const double u = uOfK[k];
    const double u1 = 1.0 - u;
    // s-edges blended in u: the t = 0 and t = 1 rows of this layer's s-edge terms.
    const double* E0 = F.u0(0, 0);
    const double* E2 = F.u0(0, nj - 1);
    const double* E4 = F.u1(0, 0);
    const double* E6 = F.u1(0, nj - 1);
    const double* T0 = F.t0(0, k);
    const double* T1 = F.t1(0, k);
    for (int n = 0; n < 3 * ni; ++n)
    {
      const double low = T0[n] - (u1 * E0[n] + u * E4[n]);
      const double high = T1[n] - (u1 * E2[n] + u * E6[n]);
      tBlendBase[n] = low;
      tBlendSlope[n] = high - low;
    }
    // u-edges at this k.
    const double* E8 = F.t0(0, k);
    const double* E9 = F.t0(ni - 1, k);
    const double* E11 = F.t1(0, k);
    const double* E10 = F.t1(ni - 1, k);

    for (int j = 1; j < nj - 1; ++j)
    {
      const double t = tOfJ[j];
      const double t1 = 1.0 - t;
      const double* S0 = F.s0(j, k);
      const double* S1 = F.s1(j, k);
      const double* E3 = F.u0(0, j);
      const double* E1 = F.u0(ni - 1, j);
      const double* E7 = F.u1(0, j);
      const double* E5 = F.u1(ni - 1, j);
      double A[3], BminusA[3];
      for (int c = 0; c < 3; ++c)
      {
        const double a = S0[c] - (u1 * E3[c] + u * E7[c]) - (t1 * E8[c] + t * E11[c]) +
          (t1 * u1 * V0[c] + t * u1 * V3[c] + t1 * u * V4[c] + t * u * V7[c]);
        const double b = S1[c] - (u1 * E1[c] + u * E5[c]) - (t1 * E9[c] + t * E10[c]) +
          (t1 * u1 * V1[c] + t * u1 * V2[c] + t1 * u * V5[c] + t * u * V6[c]);
        A[c] = a;
        BminusA[c] = b - a;
      }
      const double* bottom = F.u0(0, j);
      const double* slope = uFaceDifference + 3 * static_cast<long>(ni) * j;
      double* row = out + 3 * (plane * k + static_cast<long>(ni) * j);
      for (int i = 1; i < ni - 1; ++i)
      {
        const double s = sOfI[i];
        const int n = 3 * i;
        row[n] =
          A[0] + s * BminusA[0] + tBlendBase[n] + t * tBlendSlope[n] + bottom[n] + u * slope[n];
        row[n + 1] = A[1] + s * BminusA[1] + tBlendBase[n + 1] + t * tBlendSlope[n + 1] +
          bottom[n + 1] + u * slope[n + 1];
        row[n + 2] = A[2] + s * BminusA[2] + tBlendBase[n + 2] + t * tBlendSlope[n + 2] +
          bottom[n + 2] + u * slope[n + 2];
      }
    }
  }
}

/**
 * Interior when parallel edges carry different distributions. Each node's (s, t, u)
 * solves the coupled system
 *   s = bilinear blend in (t, u) of the four s-edge parameters at i,
 *   t = bilinear blend in (s, u) of the four t-edge parameters at j,
 *   u = bilinear blend in (s, t) of the four u-edge parameters at k,
 * the 3-D analogue of intersecting the lines joining matching edge parameters (exact
 * for the 2-D face case). Gauss-Seidel iteration from the edge averages; the map is a
 * contraction whose constant is the largest parameter difference between parallel
 * edges, so a handful of sweeps reach round-off for any sensible grading. The sweep
 * count is bounded so the result is deterministic.
 */
void interiorCoupled(const BlockFaces& F, const std::array<const double*, 12>& p, int ni, int nj,
  int kBegin, int kEnd, const std::array<double, 3>& blending, double* out)
{
  constexpr int maxSweeps = 50;
  constexpr double tolerance = 1e-15;

  const double* V[8] = { F.u0(0, 0), F.u0(ni - 1, 0), F.u0(ni - 1, nj - 1), F.u0(0, nj - 1),
    F.u1(0, 0), F.u1(ni - 1, 0), F.u1(ni - 1, nj - 1), F.u1(0, nj - 1) };
  const long plane = static_cast<long>(ni) * nj;

  for (int k = kBegin; k < kEnd; ++k)
  {
    const double c8 = p[8][k], c9 = p[9][k], c10 = p[10][k], c11 = p[11][k];
    const double* E8 = F.t0(0, k);
    const double* E9 = F.t0(ni - 1, k);
    const double* E11 = F.t1(0, k);
    const double* E10 = F.t1(ni - 1, k);
    for (int j = 1; j < nj - 1; ++j)
    {
      const double b3 = p[3][j], b1 = p[1][j], b7 = p[7][j], b5 = p[5][j];
      const double* E3 = F.u0(0, j);
      const double* E1 = F.u0(ni - 1, j);
      const double* E7 = F.u1(0, j);
      const double* E5 = F.u1(ni - 1, j);
      const double* S0 = F.s0(j, k);
      const double* S1 = F.s1(j, k);
      double* row = out + 3 * (plane * k + static_cast<long>(ni) * j);
      for (int i = 1; i < ni - 1; ++i)
      {
        const double a0 = p[0][i], a2 = p[2][i], a4 = p[4][i], a6 = p[6][i];
        double s = 0.25 * (a0 + a2 + a4 + a6);
        double t = 0.25 * (b3 + b1 + b7 + b5);
        double u = 0.25 * (c8 + c9 + c10 + c11);
        for (int sweep = 0; sweep < maxSweeps; ++sweep)
        {
          const double sNew =
            (1 - t) * (1 - u) * a0 + t * (1 - u) * a2 + (1 - t) * u * a4 + t * u * a6;
          const double tNew =
            (1 - sNew) * (1 - u) * b3 + sNew * (1 - u) * b1 + (1 - sNew) * u * b7 + sNew * u * b5;
          const double uNew = (1 - sNew) * (1 - tNew) * c8 + sNew * (1 - tNew) * c9 +
            (1 - sNew) * tNew * c11 + sNew * tNew * c10;
          const double change =
            std::max({ std::abs(sNew - s), std::abs(tNew - t), std::abs(uNew - u) });
          s = sNew;
          t = tNew;
          u = uNew;
          if (change <= tolerance)
          {
            break;
          }
        }
        s = weight(s, blending[0]);
        t = weight(t, blending[1]);
        u = weight(u, blending[2]);
        const double s1 = 1 - s, t1 = 1 - t, u1 = 1 - u;
        const double* E0 = F.u0(i, 0);
        const double* E2 = F.u0(i, nj - 1);
        const double* E4 = F.u1(i, 0);
        const double* E6 = F.u1(i, nj - 1);
        const double* T0 = F.t0(i, k);
        const double* T1 = F.t1(i, k);
        const double* U0 = F.u0(i, j);
        const double* U1 = F.u1(i, j);
        for (int c = 0; c < 3; ++c)
        {
          const double faces =
            s1 * S0[c] + s * S1[c] + t1 * T0[c] + t * T1[c] + u1 * U0[c] + u * U1[c];
          const double edges = t1 * u1 * E0[c] + t * u1 * E2[c] + t1 * u * E4[c] + t * u * E6[c] +
            s1 * u1 * E3[c] + s * u1 * E1[c] + s1 * u * E7[c] + s * u * E5[c] + s1 * t1 * E8[c] +
            s * t1 * E9[c] + s1 * t * E11[c] + s * t * E10[c];
          const double vertices = s1 * t1 * u1 * V[0][c] + s * t1 * u1 * V[1][c] +
            s * t * u1 * V[2][c] + s1 * t * u1 * V[3][c] + s1 * t1 * u * V[4][c] +
            s * t1 * u * V[5][c] + s * t * u * V[6][c] + s1 * t * u * V[7][c];
          row[3 * i + c] = faces - edges + vertices;
        }
      }
    }
  }
}
} // namespace

void transfiniteFace(const EdgeNodes& bottom, const EdgeNodes& top, const EdgeNodes& left,
  const EdgeNodes& right, double* out, std::array<Blending, 2> blending)
{
  const int ni = bottom.count;
  const int nj = left.count;
  if (ni < 2 || nj < 2)
  {
    throw GeometryError("transfinite face: each edge needs at least 2 nodes");
  }
  checkEdge(bottom, ni, "bottom");
  checkEdge(top, ni, "top");
  checkEdge(left, nj, "left");
  checkEdge(right, nj, "right");
  if (!out)
  {
    throw GeometryError("transfinite face: no output buffer");
  }

  const double* P00 = bottom.xyz;
  const double* P10 = bottom.xyz + 3 * (ni - 1);
  const double* P01 = top.xyz;
  const double* P11 = top.xyz + 3 * (ni - 1);

  std::memcpy(out, bottom.xyz, sizeof(double) * 3 * ni);
  std::memcpy(out + 3 * static_cast<long>(ni) * (nj - 1), top.xyz, sizeof(double) * 3 * ni);
  const auto interior = [&](const std::array<double, 2>& blend) {
    for (int j = 1; j < nj - 1; ++j)
    {
      double* row = out + 3 * static_cast<long>(ni) * j;
      const double* L = left.xyz + 3 * j;
      const double* R = right.xyz + 3 * j;
      copyNode(L, row);
      copyNode(R, row + 3 * (ni - 1));
      const double tL = left.params[j];
      const double tR = right.params[j];
      const double dt = tR - tL;
      for (int i = 1; i < ni - 1; ++i)
      {
        const double sB = bottom.params[i];
        const double ds = top.params[i] - sB;
        const double denominator = 1.0 - ds * dt;
        const double s = weight((sB + tL * ds) / denominator, blend[0]);
        const double t = weight((tL + sB * dt) / denominator, blend[1]);
        const double* B = bottom.xyz + 3 * i;
        const double* T = top.xyz + 3 * i;
        for (int c = 0; c < 3; ++c)
        {
          row[3 * i + c] = (1 - s) * L[c] + s * R[c] + (1 - t) * B[c] + t * T[c] -
            ((1 - s) * (1 - t) * P00[c] + s * (1 - t) * P10[c] + (1 - s) * t * P01[c] +
              s * t * P11[c]);
        }
      }
    }
  };
  std::array<double, 2> blend{ fixedBlend(blending[0]), fixedBlend(blending[1]) };
  interior(blend);
  if (blending[0] == Blending::Adaptive || blending[1] == Blending::Adaptive)
  {
    // the linear grid's lines: their spread in length decides how far to blend
    std::vector<double> across(std::max(ni, nj));
    bool again = false;
    if (blending[0] == Blending::Adaptive) // lines along i at each j
    {
      for (int j = 0; j < nj; ++j)
      {
        across[j] = 0.5 * (left.params[j] + right.params[j]);
      }
      blend[0] = adaptiveBlend(lineSpread(out, ni, nj, false, across.data()));
      again = again || blend[0] > 0.0;
    }
    if (blending[1] == Blending::Adaptive) // lines along j at each i
    {
      for (int i = 0; i < ni; ++i)
      {
        across[i] = 0.5 * (bottom.params[i] + top.params[i]);
      }
      blend[1] = adaptiveBlend(lineSpread(out, ni, nj, true, across.data()));
      again = again || blend[1] > 0.0;
    }
    if (again)
    {
      interior(blend);
    }
  }
  if (blending[0] == Blending::EndWidths) // lines along i, between the left and right edges
  {
    const double* sides[2] = { left.params, right.params };
    keepEndWidths(out, ni, nj, true, sides, bottom.params, top.params);
  }
  if (blending[1] == Blending::EndWidths) // lines along j, between the bottom and top edges
  {
    const double* sides[2] = { bottom.params, top.params };
    keepEndWidths(out, ni, nj, false, sides, left.params, right.params);
  }
}

void transfiniteBlock(const BlockBoundary& boundary, int ni, int nj, int nk, double* out)
{
  if (ni < 2 || nj < 2 || nk < 2)
  {
    throw GeometryError("transfinite block: each direction needs at least 2 nodes, got " +
      std::to_string(ni) + " x " + std::to_string(nj) + " x " + std::to_string(nk));
  }
  for (int f = 0; f < 6; ++f)
  {
    if (!boundary.faces[f])
    {
      throw GeometryError("transfinite block: face " + std::to_string(f) + " is missing");
    }
  }
  for (int e = 0; e < 12; ++e)
  {
    if (!boundary.edgeParams[e])
    {
      throw GeometryError(
        "transfinite block: edge " + std::to_string(e) + " has no distribution parameters");
    }
  }
  if (!out)
  {
    throw GeometryError("transfinite block: no output buffer");
  }

  BlockFaces faces{ { boundary.faces[0], boundary.faces[1], boundary.faces[2], boundary.faces[3],
                      boundary.faces[4], boundary.faces[5] },
    ni, nj };
  copyBoundary(faces, ni, nj, nk, out);
  if (ni < 3 || nj < 3 || nk < 3)
  {
    return;
  }

  const auto& p = boundary.edgeParams;
  std::array<double, 3> blend{ fixedBlend(boundary.blending[0]), fixedBlend(boundary.blending[1]),
    fixedBlend(boundary.blending[2]) };
  {
    // Adaptive: the spread of the lines along that direction on the four faces holding them
    // (face f's grid na x nb; the lines along b at each a, or along a at each b, weighted by
    // the mean parameters of the face's two edges across them)
    struct Lines
    {
      int face;
      bool alongB;
      int edge0, edge1;
    };
    static const std::array<std::array<Lines, 4>, 3> lines{ {
      { { { 2, false, 8, 9 }, { 3, false, 11, 10 }, { 4, false, 3, 1 }, { 5, false, 7, 5 } } },
      { { { 0, false, 8, 11 }, { 1, false, 9, 10 }, { 4, true, 0, 2 }, { 5, true, 4, 6 } } },
      { { { 0, true, 3, 7 }, { 1, true, 1, 5 }, { 2, true, 0, 4 }, { 3, true, 2, 6 } } },
    } };
    const std::array<std::array<int, 2>, 6> dims{ { { nj, nk }, { nj, nk }, { ni, nk },
      { ni, nk }, { ni, nj }, { ni, nj } } };
    std::vector<double> across;
    for (int d = 0; d < 3; ++d)
    {
      if (boundary.blending[d] != Blending::Adaptive)
      {
        continue;
      }
      double spread = 0.0;
      for (const Lines& set : lines[d])
      {
        const int na = dims[set.face][0], nb = dims[set.face][1];
        const int count = set.alongB ? na : nb;
        across.resize(count);
        for (int n = 0; n < count; ++n)
        {
          across[n] = 0.5 * (p[set.edge0][n] + p[set.edge1][n]);
        }
        spread = std::max(spread, lineSpread(boundary.faces[set.face], na, nb, set.alongB, across.data()));
      }
      blend[d] = adaptiveBlend(spread);
    }
  }
  const bool separable = sameParameters(p[0], p[2], ni) && sameParameters(p[0], p[4], ni) &&
    sameParameters(p[0], p[6], ni) && sameParameters(p[3], p[1], nj) &&
    sameParameters(p[3], p[7], nj) && sameParameters(p[3], p[5], nj) &&
    sameParameters(p[8], p[9], nk) && sameParameters(p[8], p[10], nk) &&
    sameParameters(p[8], p[11], nk);
  // F5 - F4 is the same in every k-layer.
  std::vector<double> uFaceDifference;
  if (separable)
  {
    const long plane = static_cast<long>(ni) * nj;
    uFaceDifference.resize(3 * plane);
    for (long n = 0; n < 3 * plane; ++n)
    {
      uFaceDifference[n] = faces.f[5][n] - faces.f[4][n];
    }
  }
  // Interior k-layers in chunks, on threads when a runner is installed: every node is
  // computed alone, so the chunking cannot change a bit. A quarter of a million nodes or
  // more per chunk keeps the threads' start-up negligible.
  const int layers = nk - 2;
  const long layerNodes = static_cast<long>(ni) * nj;
  const int chunks =
    static_cast<int>(chunkCount(static_cast<long>(layers) * layerNodes, 1L << 18, layers));
  forEachChunk(chunks,
    [&](long chunk)
    {
      const int kBegin = 1 + static_cast<int>(layers * chunk / chunks);
      const int kEnd = 1 + static_cast<int>(layers * (chunk + 1) / chunks);
      if (separable)
      {
        interiorSeparable(
          faces, p, ni, nj, nk, kBegin, kEnd, uFaceDifference.data(), blend, out);
      }
      else
      {
        interiorCoupled(faces, p, ni, nj, kBegin, kEnd, blend, out);
      }
    });
}
} // namespace blockforge

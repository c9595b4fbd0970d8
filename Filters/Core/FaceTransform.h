/**
 * @file FaceTransform.h
 * @brief How two blocks index a face they share (an interface, or the two faces of a
 * periodic pair): one of the 8 symmetries of a square.
 *
 * A face grid is indexed (a, b), a fastest, along the face's two index directions (see
 * model::faceDirections: i faces (j, k), j faces (i, k), k faces (i, j)). The transform
 * maps the (a, b) of one side to the (a, b) of the other. It works for node indices and
 * cell indices alike (pass node or cell counts).
 */
#pragma once

namespace blockforge
{
struct FaceTransform
{
  /// Bit 2 swaps a and b, then bits 0 and 1 flip a and b.
  int code = 0;
  bool swap() const { return (code & 4) != 0; }
  bool flipA() const { return (code & 1) != 0; }
  bool flipB() const { return (code & 2) != 0; }
  /// The other side's index of (a, b); (otherA, otherB) are the other side's counts.
  void map(int a, int b, int otherA, int otherB, int& outA, int& outB) const
  {
    const int x = swap() ? b : a;
    const int y = swap() ? a : b;
    outA = flipA() ? otherA - 1 - x : x;
    outB = flipB() ? otherB - 1 - y : y;
  }
  /// Corner c (0..3 = (0,0), (1,0), (1,1), (0,1)) mapped to the other side's corner.
  int mapCorner(int corner) const
  {
    static const int cornerA[4] = { 0, 1, 1, 0 };
    static const int cornerB[4] = { 0, 0, 1, 1 };
    int a = 0, b = 0;
    map(cornerA[corner], cornerB[corner], 2, 2, a, b);
    for (int c = 0; c < 4; ++c)
    {
      if (cornerA[c] == a && cornerB[c] == b)
      {
        return c;
      }
    }
    return -1;
  }
};
} // namespace blockforge

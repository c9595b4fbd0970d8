/**
 * @class   pqBlockForgeFirstLook
 * @brief   The GUI's first look at large BlockForge grids: Surface (coloured by block)
 *          instead of Surface With Edges above a cell count.
 *
 * BlockForge's proxies ask for Surface With Edges (their RepresentationType hints): a
 * template or a grid of up to a few hundred thousand cells shows its blocks and cells.
 * On a grid of a million cells the edges are denser than the pixels, the surface turns
 * into the edge colour, and drawing them costs on every render (measured in the GUI with
 * Benchmark/gui_apply.py: 0.33 s against 0.20 s per render at 1 M cells, and the Apply
 * that shows it 2.2 s against 1.9 s). When a representation of a BlockForge output is
 * created as Surface With Edges for data of more than LargeGridCells cells, this switches
 * it to Surface; the colouring by BlockId keeps the decomposition visible. Only the
 * first look: a type chosen later by the user is left alone.
 *
 * Registered as an auto-start of the plugin (GUI only; pvpython keeps the hint); it
 * observes the proxy manager's registrations, where the type the hint gave is set.
 */
#ifndef pqBlockForgeFirstLook_h
#define pqBlockForgeFirstLook_h

#include <QObject>

class pqBlockForgeFirstLook : public QObject
{
  Q_OBJECT
  typedef QObject Superclass;

public:
  /// Above this many cells a new representation starts as Surface.
  static constexpr long long LargeGridCells = 250000;

  pqBlockForgeFirstLook(QObject* parent = nullptr);
  ~pqBlockForgeFirstLook() override;

  void startup();
  void shutdown();

private:
  Q_DISABLE_COPY(pqBlockForgeFirstLook)
  /// The observer of the proxy manager's registrations.
  unsigned long Observer = 0;
};

#endif

/**
 * @class   pqBlockForgeHandleWidget
 * @brief   BlockOptimizer's "Manual move" group: ParaView's 3-D handle (a point widget
 *          whose position Apply projects onto the control point's carrier), which starts
 *          on the chosen control point instead of at the origin.
 *
 * ParaView's handle widget starts wherever its property says, (0, 0, 0) at first, and
 * stays hidden until "Show Point" is ticked: on a blade row the origin is on the machine
 * axis, far from every control point. This widget waits for the optimizer to locate the
 * control point named by HandleControlPoint (the information property
 * HandleControlPointPositionInfo, after an Apply) and then puts the handle on it and shows
 * it; the property is set to the same position, which the filter treats as "not moved"
 * (vtkBlockOptimizer moves the point only once the handle is dragged away from where the
 * point is), so nothing needs to be applied again. After a drag the handle stays where it
 * was dropped, as the filter projects that position on every update.
 *
 * Selected by `panel_widget="blockforge_control_point_handle"` on the property group.
 * @sa vtkBlockOptimizer, pqHandlePropertyWidget
 */
#ifndef pqBlockForgeHandleWidget_h
#define pqBlockForgeHandleWidget_h

#include "pqHandlePropertyWidget.h"

#include <QString>

class vtkEventQtSlotConnect;

class pqBlockForgeHandleWidget : public pqHandlePropertyWidget
{
  Q_OBJECT
  typedef pqHandlePropertyWidget Superclass;

public:
  pqBlockForgeHandleWidget(vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent = nullptr);
  ~pqBlockForgeHandleWidget() override;

private Q_SLOTS:
  /// After an update: puts the handle on a newly located control point.
  void controlPointLocated();

private:
  Q_DISABLE_COPY(pqBlockForgeHandleWidget);
  vtkEventQtSlotConnect* Connection;
  /// The control point the handle was last put on ("" for none).
  QString PlacedOn;
};

#endif

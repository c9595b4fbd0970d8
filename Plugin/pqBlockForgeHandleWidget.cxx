#include "pqBlockForgeHandleWidget.h"

#include "vtkCommand.h"
#include "vtkEventQtSlotConnect.h"
#include "vtkSMNewWidgetRepresentationProxy.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

namespace
{
const char* const ControlPointProperty = "HandleControlPoint";
const char* const PositionProperty = "HandlePosition";
const char* const LocatedProperty = "HandleControlPointPositionInfo";
}

pqBlockForgeHandleWidget::pqBlockForgeHandleWidget(
  vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent)
  : Superclass(proxy, group, parent)
  , Connection(vtkEventQtSlotConnect::New())
{
  // The information property changes when the proxy's information is updated after an
  // update of the pipeline (which the source proxy announces with UpdateDataEvent).
  if (vtkSMProperty* located = proxy->GetProperty(LocatedProperty))
  {
    this->Connection->Connect(
      located, vtkCommand::ModifiedEvent, this, SLOT(controlPointLocated()));
  }
  this->Connection->Connect(
    proxy, vtkCommand::UpdateDataEvent, this, SLOT(controlPointLocated()));
}

pqBlockForgeHandleWidget::~pqBlockForgeHandleWidget()
{
  this->Connection->Disconnect();
  this->Connection->Delete();
}

void pqBlockForgeHandleWidget::controlPointLocated()
{
  vtkSMProxy* proxy = this->proxy();
  vtkSMProperty* locatedProperty = proxy ? proxy->GetProperty(LocatedProperty) : nullptr;
  if (!locatedProperty || !proxy->GetProperty(ControlPointProperty))
  {
    return;
  }
  const char* chosen = vtkSMPropertyHelper(proxy, ControlPointProperty).GetAsString();
  const QString name = chosen ? QString(chosen) : QString();
  if (name.isEmpty() || name == this->PlacedOn)
  {
    return; // no point chosen, or the handle is on it already (or was dragged from it)
  }
  proxy->UpdatePropertyInformation(locatedProperty);
  double position[3] = { 0.0, 0.0, 0.0 };
  vtkSMPropertyHelper(locatedProperty).Get(position, 3);
  if (position[0] == 0.0 && position[1] == 0.0 && position[2] == 0.0)
  {
    return; // not located yet (the filter reports the origin for an unknown point)
  }
  this->PlacedOn = name;
  // The property takes the point's position: the filter does not count that as a move,
  // and the value reaches it with the next Apply.
  vtkSMPropertyHelper(proxy, PositionProperty).Set(position, 3);
  vtkSMProxy* handle = this->widgetProxy();
  vtkSMPropertyHelper(handle, "WorldPosition").Set(position, 3);
  handle->UpdateVTKObjects();
  this->setWidgetVisible(true);
  this->render();
}

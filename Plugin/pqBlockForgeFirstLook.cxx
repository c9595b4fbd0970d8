#include "pqBlockForgeFirstLook.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkPVDataInformation.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxyManager.h"
#include "vtkSMRepresentationProxy.h"
#include "vtkSMSourceProxy.h"

#include <cstring>

namespace
{
/// The proxies whose outputs are BlockForge grids and previews (XML names).
bool isBlockForgeGrid(vtkSMProxy* producer)
{
  const char* name = producer ? producer->GetXMLName() : nullptr;
  if (!name)
  {
    return false;
  }
  for (const char* known :
    { "BlockMesher", "GridQuality", "BlockOptimizer", "BlockTemplate", "BlockTemplateSource" })
  {
    if (std::strcmp(name, known) == 0)
    {
      return true;
    }
  }
  return false;
}

/// A representation registered: Surface for a large BlockForge grid shown with edges.
void representationRegistered(vtkObject*, unsigned long, void*, void* callData)
{
  const auto* registered =
    static_cast<const vtkSMProxyManager::RegisteredProxyInformation*>(callData);
  if (!registered || registered->Type != vtkSMProxyManager::RegisteredProxyInformation::PROXY ||
    !registered->GroupName || std::strcmp(registered->GroupName, "representations") != 0)
  {
    return;
  }
  vtkSMProxy* representation = registered->Proxy;
  if (!representation || !representation->GetProperty("Representation") ||
    !representation->GetProperty("Input"))
  {
    return;
  }
  vtkSMPropertyHelper input(representation, "Input");
  auto* producer = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy(0));
  if (!isBlockForgeGrid(producer))
  {
    return;
  }
  const char* type = vtkSMPropertyHelper(representation, "Representation").GetAsString();
  if (!type || std::strcmp(type, "Surface With Edges") != 0)
  {
    return;
  }
  vtkPVDataInformation* information = producer->GetDataInformation(input.GetOutputPort(0));
  if (information && information->GetNumberOfCells() > pqBlockForgeFirstLook::LargeGridCells)
  {
    vtkSMRepresentationProxy::SetRepresentationType(representation, "Surface");
    representation->UpdateVTKObjects();
  }
}
}

pqBlockForgeFirstLook::pqBlockForgeFirstLook(QObject* parent)
  : Superclass(parent)
{
}

pqBlockForgeFirstLook::~pqBlockForgeFirstLook() = default;

void pqBlockForgeFirstLook::startup()
{
  // The pipeline controller picks the representation type (the proxy's hint) before it
  // registers the representation: at the registration the type is set and nothing has
  // been rendered yet, whether the GUI's Apply or a Python Show() made it.
  vtkNew<vtkCallbackCommand> command;
  command->SetCallback(&representationRegistered);
  this->Observer = vtkSMProxyManager::GetProxyManager()->AddObserver(
    vtkCommand::RegisterEvent, command);
}

void pqBlockForgeFirstLook::shutdown()
{
  if (this->Observer && vtkSMProxyManager::IsInitialized())
  {
    vtkSMProxyManager::GetProxyManager()->RemoveObserver(this->Observer);
  }
  this->Observer = 0;
}

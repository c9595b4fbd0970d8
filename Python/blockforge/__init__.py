"""BlockForge: block-structured hexahedral grids from decomposition templates.

The VTK classes are importable directly::

    import blockforge
    source = blockforge.vtkBlockTemplateSource()

and :func:`mesh_template` runs the whole pipeline in one call.
"""
# The wrapped classes derive from these VTK modules; import them first so their
# Python types are registered.
from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkCommonExecutionModel  # noqa: F401

from .BlockForgeFilters import (  # noqa: F401
    vtkBlockMesher,
    vtkBlockTemplate,
    vtkBlockTemplateAlgorithm,
    vtkBlockTemplateSource,
    vtkGridQuality,
    vtkTurboPointSetsReader,
)

__all__ = [
    "vtkBlockMesher",
    "vtkBlockTemplate",
    "vtkBlockTemplateAlgorithm",
    "vtkBlockTemplateSource",
    "vtkGridQuality",
    "vtkTurboPointSetsReader",
    "mesh_template",
    "MIN_ANGLE_CLASSES",
]

#: Labels of the paper's MinAngle classes, in degrees.
MIN_ANGLE_CLASSES = ("0-20", "20-40", "40-60", "60-80", "80-90")


def mesh_template(template_file, parameters=None, density_multiplier=1.0):
    """Applies a template, meshes it and measures the grid.

    :param template_file: path of a BlockForge template (.yaml)
    :param parameters: dict of parameter overrides, name -> number or expression
    :param density_multiplier: scales every cell count of the template
    :returns: the vtkGridQuality algorithm after its update (port 0: the grid with the
        quality arrays; port 1: MinAngle class table; port 2: statistics table)
    :raises RuntimeError: with the template error message when a stage fails
    """
    from vtkmodules.util.misc import calldata_type
    from vtkmodules.util.vtkConstants import VTK_STRING
    from vtkmodules.vtkCommonCore import vtkCommand

    source = vtkBlockTemplateSource()
    source.SetTemplateFile(str(template_file))
    for name, value in (parameters or {}).items():
        source.SetParameter(str(name), str(value))
    mesher = vtkBlockMesher()
    mesher.SetDensityMultiplier(float(density_multiplier))
    mesher.SetInputConnection(source.GetOutputPort())
    quality = vtkGridQuality()
    quality.SetInputConnection(mesher.GetOutputPort())

    errors = []

    @calldata_type(VTK_STRING)
    def collect(_caller, _event, message):
        errors.append(message)

    for algorithm in (source, mesher, quality):
        algorithm.AddObserver(vtkCommand.ErrorEvent, collect)
    quality.Update()
    if errors:
        raise RuntimeError(errors[0].strip())
    return quality

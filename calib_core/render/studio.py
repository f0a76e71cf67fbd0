"""Lamps that light a scene as a workshop's would: several positional lights, each casting shadows, and
glossy surfaces that show highlights. The CAD views keep their even headlight; a simulated camera that
should look like a real one uses this."""

from __future__ import annotations

from dataclasses import dataclass

from calib_core.render import vtk_api as vtk
from vtkmodules.vtkRenderingOpenGL2 import vtkCameraPass, vtkRenderPassCollection, vtkSequencePass, vtkShadowMapPass


SHADOW_MAP_PX = 2048
"""The side of each lamp's shadow map (VTK's default, 256, leaves stair-stepped shadows and speckle on lit faces)."""


@dataclass(frozen=True)
class Lamp:
    """A spot lamp at ``position_mm`` (3,) in the world frame aimed at ``aim_mm`` (3,), ``intensity`` (1: full),
    lighting a cone of ``cone_deg`` (half angle, deg)."""

    position_mm: tuple[float, float, float]
    aim_mm: tuple[float, float, float]
    intensity: float = 0.7
    cone_deg: float = 50.0


@dataclass(frozen=True)
class Studio:
    """How a scene is lit: ``lamps``; ``shadows`` (each lamp casts them: shadow maps); ``ambient`` (the share of
    light that reaches what no lamp sees); surfaces' ``specular`` share and ``specular_power`` (larger: smaller,
    sharper highlights)."""

    lamps: tuple[Lamp, ...]
    ring_light: float = 0.0
    """The intensity of a light on the camera itself (a gripper camera's ring light; 0: none). It casts no shadow the
    camera could see."""
    shadows: bool = True
    ambient: float = 0.18
    specular: float = 0.45
    specular_power: float = 25.0


def light_with(renderer: vtk.vtkRenderer, studio: Studio) -> None:
    """Replace ``renderer``'s lights by ``studio``'s lamps and, with shadows, render through a shadow-map pass."""
    renderer.RemoveAllLights()
    for lamp in studio.lamps:
        light = vtk.vtkLight()
        light.SetLightTypeToSceneLight()
        light.SetPositional(True)
        light.SetPosition(*lamp.position_mm)
        light.SetFocalPoint(*lamp.aim_mm)
        light.SetConeAngle(lamp.cone_deg)
        light.SetIntensity(lamp.intensity)
        renderer.AddLight(light)
    if studio.ring_light > 0:
        ring = vtk.vtkLight()
        ring.SetLightTypeToHeadlight()
        ring.SetIntensity(studio.ring_light)
        renderer.AddLight(ring)
    if not studio.shadows:
        renderer.SetPass(None)
        return
    shadows = vtkShadowMapPass()
    shadows.GetShadowMapBakerPass().SetResolution(SHADOW_MAP_PX)
    passes = vtkRenderPassCollection()
    passes.AddItem(shadows.GetShadowMapBakerPass())
    passes.AddItem(shadows)
    sequence = vtkSequencePass()
    sequence.SetPasses(passes)
    camera_pass = vtkCameraPass()
    camera_pass.SetDelegatePass(sequence)
    renderer.SetPass(camera_pass)

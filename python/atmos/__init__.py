"""atmos: physically based rendering of atmospheric phenomena, from Python.

The smallest use::

    import atmos, numpy as np
    img = atmos.render(atmos.Scene.default(), width=64, height=48)
    rgb = np.asarray(img)[..., :3]          # (48, 64, 3) float32, linear sRGB, no copy

Scenes come from files (``Scene.load``), dicts (``Scene.from_dict``) or the default, with
keyword overrides as the CLI's ``-D``; ``Plan`` renders many frames of one scene; ``Volume``
takes NumPy arrays in and gives them back; ``mie``, ``phase_table`` and ``sky_radiance``
return arrays. Errors raise ``AtmosError`` with atmos's status code and message; a render
given ``progress=callable`` reports (stage, fraction) to it and is cancelled when it returns
False (``Cancelled``). Each thread
has its own context, and the GIL is released while the library works. docs/python.md.
"""
from atmos._core import AtmosError, AtmosTypeError, Cancelled, version
from atmos.image import Image, image_file_kind, image_kind, read_exr
from atmos.optics import mie, phase_table, refractive_index
from atmos.render import Plan, render
from atmos.scene import Scene
from atmos.sky import directions, sky_radiance
from atmos.volume import Volume

__version__ = version()
__all__ = ["AtmosError", "AtmosTypeError", "Cancelled", "Image", "Plan", "Scene", "Volume", "directions", "image_file_kind",
           "image_kind", "mie", "phase_table", "read_exr", "refractive_index", "render", "sky_radiance", "version"]

"""Plants: the linear mechanics a dynamic link acts on, one file per plant, in a registry.

Every plant follows :class:`~motionhyst.plants.registry.Plant` and is listed in
:data:`~motionhyst.plants.registry.PLANTS` under the name a scenario's ``[stage] type``
uses.

Examples
--------
>>> from motionhyst.plants import PLANTS
>>> "mass-damper" in PLANTS
True
"""

from motionhyst.plants.mass_damper import MassDamper
from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.registry import PLANTS, Plant, PlantParameter, plant_class, register

__all__ = ["PLANTS", "MassDamper", "Mechanics", "Plant", "PlantParameter", "plant_class",
           "register"]

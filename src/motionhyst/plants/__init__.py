"""Plants: the linear mechanics a dynamic link acts on, one file per plant, in a registry.

Every plant follows :class:`~motionhyst.plants.registry.Plant` and is listed in
:data:`~motionhyst.plants.registry.PLANTS` under the name a scenario's ``[stage] type``
uses: the paper's two-mass stage, single masses (with a spring, or without: a positioning
axis), a plant without inertia, a model fitted to a measured frequency response, the
measured data themselves, and any pair of python-control systems.

Examples
--------
>>> from motionhyst.plants import PLANTS
>>> list(PLANTS)                                           # doctest: +NORMALIZE_WHITESPACE
['two-mass', 'mass-spring-damper', 'mass-damper', 'quasi-static', 'modal', 'frd',
 'transfer-functions']
"""

from motionhyst.plants.two_mass import TwoMassStage  # isort: skip  (registration order)
from motionhyst.plants.mass_spring_damper import MassSpringDamper  # isort: skip
from motionhyst.plants.mass_damper import MassDamper  # isort: skip
from motionhyst.plants.quasi_static import QuasiStatic  # isort: skip
from motionhyst.plants.modal import ModalPlant, Mode  # isort: skip
from motionhyst.plants.measured import MeasuredPlant  # isort: skip
from motionhyst.plants.transfer import TransferPlant  # isort: skip
from motionhyst.plants.mechanics import Mechanics
from motionhyst.plants.registry import PLANTS, Plant, PlantParameter, plant_class, register

__all__ = ["PLANTS", "MassDamper", "MassSpringDamper", "MeasuredPlant", "Mechanics",
           "ModalPlant", "Mode", "Plant", "PlantParameter", "QuasiStatic", "TransferPlant",
           "TwoMassStage", "plant_class", "register"]

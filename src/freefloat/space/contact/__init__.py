"""Contact between bodies of one Pinocchio model (a robot's hand and a free target in the
same tree, :mod:`.target`; a link and a fixed obstacle): primitive shapes through Pinocchio's collision
library coal (:mod:`.shapes`), a compliant Hunt-Crossley normal law with regularised Coulomb
friction (:mod:`.law`), applied equal and opposite as a wrench field of the environment
(:mod:`.field`; docs/contact.md), and the latch that closes the weld on a held contact (:mod:`.latch`)."""

from .field import ContactField, ContactSettings, contact_field
from .latch import Latch, LatchWatch, close_weld
from .law import ContactLaw, restitution
from .shapes import SHAPES, Proximity, Shape, proximity
from .target import target_state, with_free_target

__all__ = ["SHAPES", "ContactField", "ContactLaw", "ContactSettings", "Latch", "LatchWatch", "Proximity", "Shape",
           "close_weld", "contact_field", "proximity", "restitution", "target_state", "with_free_target"]

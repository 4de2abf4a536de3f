"""Contact between bodies of one Pinocchio model (a robot's hand and a target on a second
free-flyer root, a link and a fixed obstacle): primitive shapes through Pinocchio's collision
library coal (:mod:`.shapes`), a compliant Hunt-Crossley normal law with regularised Coulomb
friction (:mod:`.law`), applied equal and opposite as a wrench field of the environment
(:mod:`.field`; docs/contact.md)."""

from .field import ContactField, ContactSettings, contact_field
from .law import ContactLaw, restitution
from .shapes import SHAPES, Proximity, Shape, proximity

__all__ = ["SHAPES", "ContactField", "ContactLaw", "ContactSettings", "Proximity", "Shape", "contact_field",
           "proximity", "restitution"]

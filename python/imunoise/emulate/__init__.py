"""An emulated VN-100 on a pseudo-terminal, for tests and demos (``imunoise emulate``).

See :mod:`imunoise.emulate.device`.
"""

from imunoise.emulate.device import FAULT_KINDS, Emulator, Event, Fault

__all__ = ["FAULT_KINDS", "Emulator", "Event", "Fault"]

"""The cyclic biaxial test: the biaxial test's sample, consolidation and flexible
boundary, then the platens driven between +/- an axial strain amplitude for a
number of cycles at the constant confining pressure (``grainlab run cyclic``;
docs/protocols.md)."""

from grainlab.protocols.cyclic.protocol import CyclicProtocol, run_cyclic

__all__ = ["CyclicProtocol", "run_cyclic"]

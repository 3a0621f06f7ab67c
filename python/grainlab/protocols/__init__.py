"""Protocols: what drives the engine through a test (sample, consolidation, boundary, shearing)."""

"""Fuzzed particles CSV and LAMMPS dump inputs: every mutation of a valid file
either reads as a snapshot or is refused with grainlab's documented reader
error, :class:`grainlab.io.FileFormatError`, whose message starts with the file
(``FILE:LINE: problem``); no other exception type, no crash (docs/analysis.md,
files read and written)."""

from __future__ import annotations

import random

import numpy as np
import pytest
from reliability_factories import CONTACTS_CSV, CSV, DUMP, LOCAL_DUMP

from grainlab.io import FileFormatError, read_snapshot

#: Tokens that a damaged or hand-edited file holds where a number or a flag belongs.
TOKENS = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e400", "abc", "", "pp", "ff", "xy",
          "1e-300", "3", "0.0050", "ITEM:", "ITEM: TIMESTEP", "\ufeff", ",", "  ", "1,2", "9" * 30]


def _mutate(text: str, rng: random.Random) -> str:
    lines = text.split("\n")
    for _ in range(rng.randint(1, 3)):
        kind = rng.randrange(8)
        k = rng.randrange(len(lines))
        if kind == 0:  # a token replaced
            sep = "," if "," in lines[k] else " "
            fields = lines[k].split(sep)
            fields[rng.randrange(len(fields))] = rng.choice(TOKENS)
            lines[k] = sep.join(fields)
        elif kind == 1:
            del lines[k]
        elif kind == 2:
            lines.insert(k, lines[rng.randrange(len(lines))])
        elif kind == 3:
            j = rng.randrange(len(lines))
            lines[k], lines[j] = lines[j], lines[k]
        elif kind == 4:  # truncated anywhere
            joined = "\n".join(lines)
            return joined[: rng.randrange(len(joined) + 1)]
        elif kind == 5:  # a field dropped or added
            sep = "," if "," in lines[k] else " "
            fields = lines[k].split(sep)
            if rng.random() < 0.5 and len(fields) > 1:
                del fields[rng.randrange(len(fields))]
            else:
                fields.insert(rng.randrange(len(fields) + 1), rng.choice(TOKENS))
            lines[k] = sep.join(fields)
        elif kind == 6:  # one character changed
            if lines[k]:
                c = rng.randrange(len(lines[k]))
                lines[k] = lines[k][:c] + rng.choice("0123456789.-e+ ,x\t") + lines[k][c + 1 :]
        else:  # Windows line endings or a byte-order mark
            return ("\ufeff" if rng.random() < 0.5 else "") + "\r\n".join(lines)
    return "\n".join(lines)


CASES = {
    "particles.csv": (CSV, None, {}),
    "atoms.dump": (DUMP, None, {}),
    "atoms-first.dump": (DUMP, 0, {}),
    "contacts.csv": (CONTACTS_CSV, None, {"particles": CSV}),
    "contacts.dump": (LOCAL_DUMP, None, {"atoms": DUMP}),
}


@pytest.mark.parametrize("name", list(CASES))
def test_mutated_inputs_read_or_raise_the_documented_error(tmp_path, name):
    source, timestep, companions = CASES[name]
    rng = random.Random(f"grainlab-fuzz-{name}")
    outcomes = {"read": 0, "refused": 0}
    for case in range(120):
        text = _mutate(source, rng)
        path = tmp_path / f"{case:03d}-{name}"
        path.write_bytes(text.encode("utf-8", errors="surrogatepass"))
        try:
            if "particles" in companions:  # the contacts file is the one mutated
                other = tmp_path / "particles.csv"
                other.write_text(companions["particles"])
                snap = read_snapshot(other, contacts=path)
            elif "atoms" in companions:
                other = tmp_path / "atoms.dump"
                other.write_text(companions["atoms"])
                snap = read_snapshot(other, contacts=path)
            else:
                snap = read_snapshot(path, timestep=timestep)
        except FileFormatError as error:
            assert str(error).startswith(str(path)), (text, str(error))
            assert "np.float64" not in str(error) and "np.int64" not in str(error), str(error)
            outcomes["refused"] += 1
            continue
        except Exception as error:  # noqa: BLE001 - the failure this test exists to find
            pytest.fail(f"{type(error).__name__}: {error}\n--- input ---\n{text}")
        # what reads is a usable snapshot: finite, positive radii, valid contacts with defined normals
        assert np.all(np.isfinite(snap.positions)) and np.all(snap.radii > 0)
        if snap.n_contacts:
            assert np.all(np.isfinite(snap.contact_normals()))
        outcomes["read"] += 1
    # the mutations are neither all harmless nor all fatal
    assert outcomes["read"] > 10 and outcomes["refused"] > 10, outcomes

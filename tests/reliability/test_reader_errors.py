"""What the CSV and LAMMPS dump readers refuse, and what they accept, found by a
probe of damaged and unusual inputs: every refusal names the file and line."""

from __future__ import annotations

import numpy as np
import pytest
from reliability_factories import ATOM_COLUMNS, CSV, DUMP, dump_frame

from grainlab.cli import main
from grainlab.io import FileFormatError, list_timesteps, read_snapshot


def _refused(path, line, *needles):
    with pytest.raises(FileFormatError) as info:
        read_snapshot(path)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}: "), message
    for needle in needles:
        assert needle in message, message
    return message


@pytest.mark.parametrize(
    ("flags", "shown"), [("pp", "'pp'"), ("", "'none'"), ("pq pp pp", "'pq pp pp'"), ("pp ff", "'pp ff'"),
                         ("pf ff pp", "'pf ff pp'")]
)
def test_box_flags_that_do_not_say_which_directions_are_periodic_are_refused(tmp_path, flags, shown):
    path = tmp_path / "atoms.dump"
    path.write_text(DUMP.replace("ITEM: BOX BOUNDS pp ff pp", f"ITEM: BOX BOUNDS {flags}".rstrip()))
    _refused(path, 5, "expected three boundary flags", f"found {shown}", "periodic")


def test_the_box_flags_decide_the_contacts_across_the_box(tmp_path):
    """Atoms 1 and 2 (x = 0.0001 and 0.0096 in a 10 mm box) touch only through the periodic x."""
    periodic, walled = tmp_path / "p.dump", tmp_path / "f.dump"
    periodic.write_text(DUMP)
    walled.write_text(DUMP.replace("pp ff pp", "ff ff pp"))

    def pairs(path):
        s = read_snapshot(path)
        return {tuple(sorted(s.ids[[i, j]])) for i, j in zip(s.contact_i, s.contact_j, strict=True)}

    assert (1, 2) in pairs(periodic) and (1, 2) not in pairs(walled)


def test_an_inverted_or_empty_box_names_its_line(tmp_path):
    path = tmp_path / "atoms.dump"
    path.write_text(DUMP.replace("0.0 0.01\n0.0 0.01\n", "0.0 0.01\n0.01 0.0\n", 1))
    _refused(path, 7, "ylo 0.01 and yhi 0", "ylo < yhi")
    path.write_text(DUMP.replace("0.0 0.01\n", "0.005 0.005\n", 1))
    _refused(path, 6, "xlo 0.005 and xhi 0.005")


def test_a_timestep_given_twice_is_refused(tmp_path):
    path = tmp_path / "atoms.dump"
    path.write_text(DUMP.replace("ITEM: TIMESTEP\n100\n", "ITEM: TIMESTEP\n0\n"))
    message = _refused(path, 14, "timestep 0 again", "first frame starts on line 1", "ambiguous")
    assert "frame" in message
    with pytest.raises(FileFormatError, match="timestep 0 again"):
        list_timesteps(path)


@pytest.mark.parametrize("cut", ["ITEM: ATOMS id type x y z radius vx vy\n4 1", "ITEM: NUMBER OF ATOMS\n",
                                 "ITEM: TIMESTEP\n"])
def test_an_intact_frame_of_a_truncated_dump_reads(tmp_path, cut):
    path = tmp_path / "atoms.dump"
    second = DUMP.index("ITEM: TIMESTEP\n100")
    path.write_text(DUMP[: DUMP.index(cut, second) + len(cut)])
    first = read_snapshot(path, timestep=0)
    whole = tmp_path / "whole.dump"
    whole.write_text(DUMP)
    np.testing.assert_array_equal(first.positions, read_snapshot(whole, timestep=0).positions)
    assert list_timesteps(path) == [0]
    with pytest.raises(FileFormatError, match=r"file ends .*; the intact frames are at timesteps 0$"):
        read_snapshot(path)  # the last frame, the cut one
    assert main(["analyze", str(path), "--timestep", "0", "--no-figures", "--out", str(tmp_path / "a")]) == 0


def test_a_csv_with_a_byte_order_mark_reads_like_one_without(tmp_path):
    plain, marked = tmp_path / "plain.csv", tmp_path / "excel.csv"
    plain.write_text(CSV)
    marked.write_bytes(b"\xef\xbb\xbf" + CSV.replace("\n", "\r\n").encode())  # Excel's "CSV UTF-8"
    a, b = read_snapshot(plain), read_snapshot(marked)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.ids, b.ids)
    assert a.n_contacts == b.n_contacts > 0


def test_numbers_in_messages_are_plain(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text(CSV.replace("2,0.0019,0.0010", "2,nan,0.0010"))
    _refused(path, 3, "column 'x': value nan is not finite")
    path.write_text(CSV.replace("\n3,", "\n3.5,"))
    _refused(path, 4, "column 'id': 3.5 is not an integer id")
    path.write_text(CSV.replace("0.0004", "-0.0004"))
    _refused(path, 5, "column 'radius': -0.0004 is not > 0")


def test_huge_coordinates_and_coincident_centres_name_their_line(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text(CSV.replace("3,0.0010,0.0019", "3,1e300,0.0019"))
    _refused(path, 4, "column 'x': 1e+300 m is beyond the 1e+12 m grainlab reads")
    path.write_text(CSV.replace("3,0.0010,0.0019", "3,0.0019,0.0010"))  # on particle 2's centre
    _refused(path, 4, "the centre of the particle on line 3 too", "no contact normal")
    dump = tmp_path / "atoms.dump"
    dump.write_text(dump_frame(5, "ATOMS", ATOM_COLUMNS, ["1 1 0.004 0.005 0 0.0005 0 0",
                                                         "2 1 0.004 0.005 0 0.0004 0 0"]))
    _refused(dump, 11, "the centre of the particle on line 10 too")


def test_analyze_says_what_is_wrong_in_one_line(tmp_path, capsys):
    path = tmp_path / "atoms.dump"
    path.write_text(DUMP.replace("ITEM: BOX BOUNDS pp ff pp", "ITEM: BOX BOUNDS pp"))
    assert main(["analyze", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{path}:5: expected three boundary flags" in err
    assert main(["analyze", str(path), "--bins", "100000000"]) == 2
    assert "--bins: must be an integer from 2 to 3600, got 100000000" in capsys.readouterr().err

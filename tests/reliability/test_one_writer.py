"""One writer per results folder: a second run on a folder being written is refused at once,
with one line, and nothing is written; the lock dies with its holder (no stale lock); a killed
campaign leaves no worker writing on into its runs."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from grainlab.cli import main
from grainlab.io.results import FolderBusyError, writer_lock

#: Holds the writer lock of a folder until killed; prints "held" once it has it.
HOLDER = """\
import sys, time
from grainlab.io.results import writer_lock
with writer_lock(sys.argv[1]):
    print("held", flush=True)
    time.sleep(120)
"""


def _hold(folder):
    holder = subprocess.Popen([sys.executable, "-c", HOLDER, str(folder)], stdout=subprocess.PIPE, text=True)
    assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
    return holder


def _end(holder):
    holder.send_signal(signal.SIGKILL)
    holder.wait(timeout=30)
    holder.stdout.close()


def test_a_second_writer_is_refused_and_a_dead_holders_lock_is_free(tmp_path):
    folder = tmp_path / "run"
    folder.mkdir()
    holder = _hold(folder)
    try:
        with pytest.raises(FolderBusyError, match="being written by another grainlab run"), writer_lock(folder):
            pass
    finally:
        _end(holder)
    with writer_lock(folder):  # the kernel released it with the dead holder: no stale lock
        with pytest.raises(FolderBusyError):  # and a lock is per open file: the same process twice is refused
            with writer_lock(folder):
                pass


def test_grainlab_biaxial_on_a_folder_being_written_says_so_and_writes_nothing(tmp_path, capsys):
    folder = tmp_path / "run"
    folder.mkdir()
    holder = _hold(folder)
    try:
        for argv in (["biaxial", "--quick", "--out", str(folder), "--no-report"],
                     ["biaxial", "--quick", "--out", str(folder), "--resume"]):
            assert main(argv) == 2
            err = capsys.readouterr().err.strip().splitlines()
            assert len(err) == 1 and "being written by another grainlab run" in err[0] and str(folder) in err[0]
            assert list(folder.iterdir()) == []
    finally:
        _end(holder)


#: A pool of campaign-style workers (the campaign's initializer) on a long task; prints their
#: process ids and kills itself.
KILLED_CAMPAIGN = textwrap.dedent("""\
    import multiprocessing, os, signal, time
    from concurrent.futures import ProcessPoolExecutor
    from grainlab._child import die_with_parent
    if __name__ == "__main__":
        pool = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=die_with_parent, initargs=(os.getpid(),))
        futures = [pool.submit(time.sleep, 60) for _ in range(2)]
        time.sleep(3)
        print(*pool._processes, flush=True)
        os.kill(os.getpid(), signal.SIGKILL)
    """)


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as stat:  # a zombie has ended
        return stat.read().split(")")[-1].split()[0] != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_campaign_workers_end_with_their_parent(tmp_path):
    script = tmp_path / "killed.py"
    script.write_text(KILLED_CAMPAIGN)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60, check=False)
    pids = [int(p) for p in done.stdout.split()]
    assert len(pids) == 2, done.stderr
    deadline = time.monotonic() + 20
    while any(_alive(p) for p in pids) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(p) for p in pids)


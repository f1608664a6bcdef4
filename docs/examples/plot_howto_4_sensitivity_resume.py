"""
How-to 4: a sensitivity study, interrupted and resumed
======================================================

**You have** a case file whose estimate you trust statistically (its interval, how-to 1), and
a nagging doubt: the bridge's frequency, damping and modal mass, and the crowd's step
frequencies, are only known to a percent or so. How much does the estimate move when they are
off?

**You get** the estimation error Δ of f_h1 and ξ_h1 per modelling error, the bound "nominal ±
the largest Δ", and that bound together with the record's statistical interval (theory:
:ref:`theory-modelling-errors`). A study is dozens of estimations, minutes to hours: this guide
shows how to stop it (Ctrl-C, a lost connection, a reboot) and go on without redoing what was
done.

In a terminal::

    crowdvib sensitivity paper_example.toml --out study
    ^C                                   # interrupted: the finished tasks stay in study/tasks
    crowdvib sensitivity paper_example.toml --out study --resume

The case is ``examples/paper_example.toml`` of the repository, with its one-hour record.
"""

# %%
# The case
# --------
# We copy the case and its record into a fresh folder. To keep this page fast, the case states
# the paper's least-squares estimator (a fraction of a second per estimation), and the study runs
# in this process (``--workers 1``) with the individual errors only (``--no-joint``: the 2⁵ sign
# combinations per level are 64 more estimations) and without the record-length study. Your
# study would keep crowdvib's default estimator and all of it.
import contextlib
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import matplotlib.pyplot as plt

from crowdvib import load_case
from crowdvib.cases import case_estimator, measure_case
from crowdvib.cli import main
from crowdvib.runner import TaskStore
from crowdvib.studies import modelling_error_study

try:
    examples = Path(__file__).resolve().parents[2] / "examples"    # the repository's
except NameError:                # sphinx-gallery runs the cells in docs/examples, no __file__
    examples = Path.cwd().resolve().parents[1] / "examples"
workdir = tempfile.TemporaryDirectory(prefix="crowdvib-howto-")   # removed at exit
folder = Path(workdir.name)
shutil.copy(examples / "paper_example_record.npz", folder)
text = (examples / "paper_example.toml").read_text(encoding="utf-8")
(folder / "paper_example.toml").write_text(
    text.replace("[estimation]\n", '[estimation]\nmethod = "least_squares"   # fast, for this '
                                   'page\n'), encoding="utf-8")


def run(command_line):
    """Run a crowdvib command line as typed in a terminal; print what it prints there."""
    print(f"$ {command_line}")
    # In the guide's folder (sphinx-gallery runs each cell in docs/examples); a terminal shows
    # both streams.
    with contextlib.chdir(folder), contextlib.redirect_stderr(sys.stdout):
        return main(shlex.split(command_line)[1:])


# %%
# Start the study, and interrupt it
# ---------------------------------
# Every finished estimation ("task") is written at once to ``study/tasks``, one file each, under
# a key made from all its inputs. Here the study runs as a separate process, and when eight
# tasks are done we send it what Ctrl-C sends: SIGINT. It stops, keeps what is done, exits with
# status 130 and prints the command that resumes it.
command = ("crowdvib sensitivity paper_example.toml --out study --workers 1 --no-joint "
           "--no-record-length")
print(f"$ {command}")
study = subprocess.Popen([sys.executable, "-m", "crowdvib", *shlex.split(command)[1:]], cwd=folder,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
tasks = folder / "study/tasks"
while study.poll() is None and len(list(tasks.glob("*.json"))) < 8:
    time.sleep(0.05)
study.send_signal(signal.SIGINT)                 # Ctrl-C
printed, _ = study.communicate()
print(printed)
print("exit status", study.returncode)
kept = {path.name: path.stat().st_mtime_ns for path in tasks.glob("*.json")}
print(f"{len(kept)} finished task(s) in study/tasks")

# %%
# Resume
# ------
# The same command with ``--resume`` (``--workers`` may differ: the results do not depend on
# it). It reads the finished tasks back and computes only the rest. A task whose inputs changed
# since (you edited the case, replaced the record) is computed again, and the command says how
# many. ``--force`` would start afresh instead.
status = run(command + " --resume")
print("exit status", status)
untouched = sum(tasks.joinpath(name).stat().st_mtime_ns == mtime for name, mtime in kept.items())
print(f"{untouched} of the {len(kept)} tasks of the first run reused as they were; "
      f"{len(list(tasks.glob('*.json'))) - len(kept)} computed on resuming")

# %%
# What to look at: each modelling error's Δ (the structural frequency matters most: 1 % on the
# bridge's frequency moves ξ_h1 by much more than its statistical interval), the ``result`` line
# (nominal ± the largest Δ at the highest level; the joint bound when the joint cases are run),
# and the last two lines, the record's 95 % interval widened by that bound. The figure
# ``study/estimation_errors.png``:
figure, axes = plt.subplots(figsize=(8, 4.5))
axes.imshow(plt.imread(folder / "study/estimation_errors.png"))
axes.set_axis_off()

# %%
# The same from Python
# --------------------
# :func:`crowdvib.studies.modelling_error_study` takes the store as ``store=``: a second
# call with the same store resumes. Here the first call is stopped after three tasks, as Ctrl-C
# would (its ``progress`` callback raises ``KeyboardInterrupt``), on a smaller study: the
# structural frequency and damping at one level each.
case = load_case(folder / "paper_example.toml")
measured = measure_case(case).psd
levels = {"frequencies": (0.01,), "damping_ratios": (0.1,)}
# The case's own estimator (its [estimation] table as one value), least squares as stated there.
options = dict(estimator=case_estimator(case), levels=levels, joint=False,
               store=TaskStore(folder / "python_study"))


def stop_after_three(done, total):
    if done == 3:
        raise KeyboardInterrupt


try:
    modelling_error_study(measured, case.structure, case.crowd, progress=stop_after_three,
                          **options)
except KeyboardInterrupt:
    print(f"interrupted: {len(options['store'].keys())} task(s) stored")

counts = []
result = modelling_error_study(measured, case.structure, case.crowd,
                               progress=lambda done, total: counts.append((done, total)),
                               **options)
print(f"resumed: {counts[0][0]} of {counts[0][1]} tasks read back, "
      f"{counts[-1][0] - counts[0][0]} computed")
summary = result.summary()
print(f"f_h1 = {summary['frequency']['nominal']:.2f} ± {summary['frequency']['bound']:.2f} Hz, "
      f"ξ_h1 = {summary['damping_ratio']['nominal']:.2f} ± "
      f"{summary['damping_ratio']['bound']:.2f}  (nominal ± largest |Δ|)")

"""Read a 1-hour, 2-channel, 200 Hz record and compute its PSDs (issue 4; target <= 2 s).

    python benchmarks/bench_records.py [--json results.json]

For every record format: the time to read the file (with the time-stamp checks), to check the
samples, and to compute the 10 Hz low-passed Welch PSD (T = 60 s) plus the convergence curve
(docs: theory, Welch PSDs, filters and convergence). Writing the files is not timed. Prints a table (and optionally JSON); asserts
nothing.
"""

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from crowdvib import LowPassFilter, Record, check_record, psd_convergence, read_record, \
    welch_psd, write_record

DURATION, SAMPLE_RATE, WINDOW = 3600.0, 200.0, 60.0
FORMATS = [("npz", "record.npz"), ("mat", "record.mat"), ("mat73", "record_v73.mat"),
           ("uff", "record.uff"), ("csv", "record.csv")]
TARGET = 2.0


def _best_of(function, repeat=3):
    best, value = np.inf, None
    for _ in range(repeat):
        started = time.perf_counter()
        value = function()
        best = min(best, time.perf_counter() - started)
    return best, value


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, default=None, help="also write the rows as JSON")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(2023)
    n = int(DURATION * SAMPLE_RATE)
    record = Record(rng.normal(scale=0.02, size=(2, n)), SAMPLE_RATE, ("main_span", "side_span"))
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for fmt, name in FORMATS:
            path = write_record(record, Path(directory) / name, format=fmt)
            size = path.stat().st_size / 1e6
            read_s, loaded = _best_of(lambda: read_record(path))
            check_s, _ = _best_of(lambda: check_record(loaded, band=(2.0, 10.0)))
            lowpass = LowPassFilter(10.0, 4, loaded.sample_rate)
            psd_s, _ = _best_of(lambda: welch_psd(loaded.data, loaded.sample_rate,
                                                  window_length=WINDOW, lowpass=lowpass))
            conv_s, _ = _best_of(lambda: psd_convergence(loaded.data, loaded.sample_rate,
                                                         window_length=WINDOW, band=(2.0, 6.0),
                                                         lowpass=lowpass))
            total = read_s + check_s + psd_s + conv_s
            rows.append({"format": fmt, "size_mb": size, "read_s": read_s, "check_s": check_s,
                         "welch_s": psd_s, "convergence_s": conv_s, "total_s": total,
                         "within_target": total <= TARGET})
    print(f"1-hour, 2-channel, {SAMPLE_RATE:g} Hz record ({n} samples per channel), "
          f"Welch T = {WINDOW:g} s, 10 Hz low-pass; best of 3; target total <= {TARGET:g} s")
    print(f"{'format':>7s} {'MB':>6s} {'read':>7s} {'check':>7s} {'welch':>7s} {'converg.':>8s} "
          f"{'total [s]':>9s}")
    for row in rows:
        print(f"{row['format']:>7s} {row['size_mb']:6.1f} {row['read_s']:7.3f} "
              f"{row['check_s']:7.3f} {row['welch_s']:7.3f} {row['convergence_s']:8.3f} "
              f"{row['total_s']:9.3f}{'' if row['within_target'] else '  (over target)'}")
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()

"""Fuzzing every record reader (CSV, NPZ, MAT v5, MAT v7.3 through h5py, UFF 58 through pyuff):
only crowdvib errors may come out (issue 9, fault 6: BadZipFile, zlib.error, EOFError, MatReadError,
h5py's OSError, UnicodeDecodeError, IndexError … escaped before)."""

import numpy as np
import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, random_bytes, read_damaged, small_record
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import read_record, write_record
from crowdvib.errors import DataError

pytestmark = pytest.mark.fuzz

#: format → file name crowdvib writes it under
FILES = {"csv": "record.csv", "npz": "record.npz", "mat": "record.mat", "mat73": "record.mat",
         "uff": "record.uff"}


@pytest.fixture(scope="module", params=list(FILES))
def fmt(request):
    if request.param == "mat73":
        pytest.importorskip("h5py")
    if request.param == "uff":
        pytest.importorskip("pyuff")
    return request.param


@pytest.fixture(scope="module")
def good(tmp_path_factory, fmt):
    """A file crowdvib wrote in the format (the seed of every mutation)."""
    path = write_record(small_record(), tmp_path_factory.mktemp(f"good_{fmt}") / FILES[fmt],
                        format=fmt)
    return path.read_bytes()


@pytest.fixture(scope="module")
def target(tmp_path_factory, fmt):
    return tmp_path_factory.mktemp(f"fuzz_{fmt}") / f"damaged_{FILES[fmt]}"


def test_the_seed_file_reads_back(good, target, fmt):
    # Reference: the record written by small_record(), read through the same helper.
    record = read_damaged(target, good, format=fmt)
    assert record is not None and record.channel_names == ("main", "side", "deck")


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes(target, fmt, content):
    read_damaged(target, content, format=fmt)


@FUZZ
@given(data=st.data())
def test_damaged_file(good, target, fmt, data):
    read_damaged(target, data.draw(mutations(good)), format=fmt)


# ----------------------------------------------------------- CSV shapes of other programs
#: Header names: crowdvib's own, usual time headers, and names that collide with them.
HEADER_NAMES = st.sampled_from(["time", "t", "Time [s]", "Zeit", "time [ms]", "a", "b", "Sensor 1",
                                "a,b", "=x", "'=x", "", "T"])


@st.composite
def csv_texts(draw):
    """(text, regular): a CSV with ``,``, ``;`` or tab between columns, decimal points or commas,
    and header names that may repeat or look like time (issue 24). ``regular`` when the file
    follows the documented layout: one "time" column, unique names, one decimal mark that the
    separator allows."""
    delimiter = draw(st.sampled_from([",", ";", "\t"]))
    mark = draw(st.sampled_from([".", ","]))
    names = ["time"] + draw(st.lists(HEADER_NAMES, min_size=1, max_size=4))
    rows = draw(st.integers(0, 6))
    values = draw(st.lists(st.floats(-10, 10, allow_nan=False).map(lambda v: round(v, 3)),
                           min_size=rows * (len(names) - 1), max_size=rows * (len(names) - 1)))
    cells = [[f"{i / 50:g}"] + [f"{v:g}" for v in values[i * (len(names) - 1):
                                                          (i + 1) * (len(names) - 1)]]
             for i in range(rows)]
    lines = [delimiter.join(f'"{n}"' if delimiter in n else n for n in names)]
    lines += [delimiter.join(cell.replace(".", mark) for cell in row) for row in cells]
    timeish = [n for n in names[1:] if n in ("time", "t", "Time [s]", "Zeit", "time [ms]")]
    regular = (rows >= 2 and len({n.lstrip("'") for n in names}) == len(names) and not timeish
               and not (mark == "," and delimiter == ",")
               and not (mark == "," and any("." in n for n in names))
               and not any("," in n and delimiter != "," for n in names))
    return "\n".join(lines) + "\n", regular, np.array(values).reshape(rows, len(names) - 1).T


@FUZZ
@given(shape=csv_texts())
def test_csv_shapes(tmp_path_factory, shape):
    # Reference: the CSV layout of crowdvib.io.formats: a regular file reads back its numbers,
    # any other gives a crowdvib error or a record that satisfies the invariants.
    text, regular, data = shape
    path = tmp_path_factory.getbasetemp() / "shapes.csv"
    path.write_text(text, encoding="utf-8")
    record = read_damaged(path, path.read_bytes())
    if regular:
        assert record is not None, text
        np.testing.assert_allclose(record.data, data)
        assert record.sample_rate == pytest.approx(50.0)


@FUZZ_RANDOM
@given(dtype=st.sampled_from(["int8", "int16", "int32", "int64", "uint16", "float32",
                              "float64"]))
def test_npz_sample_types(tmp_path_factory, dtype):
    # Issue 24: integer samples are a logger's raw counts, refused naming the type; floating
    # point samples are read as they are.
    path = tmp_path_factory.getbasetemp() / "types.npz"
    np.savez(path, data=(np.arange(12) % 5).astype(dtype).reshape(2, 6), sample_rate=50.0)
    if dtype.startswith(("int", "uint")):
        with pytest.raises(DataError, match=rf"types.npz: data holds {dtype} samples"):
            read_record(path)
    else:
        np.testing.assert_array_equal(read_record(path).data[1], [1, 2, 3, 4, 0, 1])

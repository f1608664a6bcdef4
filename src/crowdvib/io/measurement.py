"""A case's measured records, read, merged, checked and pre-processed (docs: theory, Welch PSDs, filters and convergence)."""

from ..errors import ParameterError
from ..signals import detrend, resample, stationary_time_frame
from ._common import named_file
from .gaps import mend_gaps
from .records import check_record, merge_records, read_record

__all__ = ["load_measurement"]


def load_measurement(case, *, band=None):
    """Read, merge, check and pre-process the records of a case (``[measurement]``).

    Steps (docs: theory, Welch PSDs, filters and convergence): read every file (channels mapped to output names, units converted to
    m/s²), merge the files' channels, cut at or bridge dropouts if ``gaps`` says so
    (:func:`crowdvib.io.gaps.mend_gaps`, stated in the record's notes), check the samples (:func:`crowdvib.io.records.check_record`,
    Nyquist above ``band``'s upper edge and the filter cut-off), cut the time frame (explicit, or
    the longest stationary stretch), remove the trend and resample if asked. The low-pass filter
    is *not* applied here: :func:`crowdvib.welch_psd` applies it and records it in the PSD, so the
    model can apply the same filter.

    Parameters
    ----------
    case : Case
    band : (float, float), optional
        Analysis band [Hz] (default the case's estimation band).

    Returns
    -------
    Record
    """

    spec = case.measurement
    if not spec.files:
        raise ParameterError(f"{case.path.name if case.path else case.name}: measurement.files "
                             "is empty: the case has no record to read")
    records = []
    for number, file in enumerate(spec.files):
        named_file(file, f"{case.path.name}: measurement.files[{number}]")
        record = read_record(file, format=spec.format, units=spec.units,
                             sample_rate=spec.sample_rate, time_column=spec.time_column,
                             header_row=spec.header_row)
        if spec.channels is not None:
            wanted = {out: name for out, name in spec.channels.items()
                      if name in record.channel_names}
            if len(spec.files) == 1 and len(wanted) != len(spec.channels):
                record.select(spec.channels)     # raises, naming the missing channel
            record = record.select(wanted) if wanted else None
        if record is not None:
            records.append(record)
    record = mend_gaps(merge_records(records), spec.gaps, spec.max_gap)
    band = case.estimation.band if band is None else band
    upper = max(band[1], spec.lowpass_cutoff or 0.0)
    check_record(record, band=(band[0], upper))
    if spec.time_frame == "stationary":
        start, end = stationary_time_frame(record.data, record.sample_rate,
                                           block_length=spec.window_length)
        record = record.frame(record.start_time + start, record.start_time + end)
    elif spec.time_frame is not None:
        record = record.frame(*spec.time_frame)
    data = detrend(record.data, spec.detrend)
    rate = record.sample_rate
    if spec.resample is not None:
        data, rate = resample(data, rate, spec.resample)
        if rate / 2 <= upper:
            raise ParameterError(f"{case.path.name}: measurement.resample {spec.resample:g} Hz "
                                 f"puts the Nyquist frequency below {upper:g} Hz")
    return record.replace(data=data, sample_rate=rate)

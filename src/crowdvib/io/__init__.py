"""Files in and out: measured records, TOML case files, modal-model tables and FE exports, and
a monitoring season's crowd tables."""

from .casefile import Case, load_case, paper_example_case
from .crowdtable import CrowdTable, read_crowd_table
from .femodes import FEModes, read_fe_modes
from .measurement import load_measurement
from .modalfiles import read_modal_model, write_modal_model
from .records import (RECORD_FORMATS, Record, check_record, convert_units, merge_records,
                      read_record, write_record)

__all__ = ["Record", "read_record", "write_record", "check_record", "merge_records",
           "convert_units", "RECORD_FORMATS", "Case", "load_case", "load_measurement",
           "paper_example_case", "read_modal_model", "write_modal_model", "FEModes",
           "read_fe_modes", "read_crowd_table", "CrowdTable"]

"""Writes the seeds of the `dicom` fuzz target (fuzz/corpus/dicom, FUZZING.md).

Copies a few small greyscale files of pydicom's test data (one per transfer syntax the
reader decodes) and writes, with pydicom, a three-slice series of 4 x 4 CT slices whose
files are joined by the target's separator (fuzz/src/dicom.rs), so that the fuzzer starts
from a series as well as from single files.

    python fuzz/dicom_seeds.py fuzz/corpus/dicom    # needs pydicom (py/requirements-test.txt)
"""

import io
import shutil
import sys
from pathlib import Path

import numpy as np
import pydicom
from pydicom.data import get_testdata_file
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

SEPARATOR = b"@@next-dicom-file@@"

# pydicom's test files (MIT licence, pydicom/data/test_files): greyscale, under 10 KB. The
# `seed_` files are read whole (tests/fuzz_corpus.rs checks it); the dose grids have 32-bit
# samples, which the reader refuses by name, and seed the fuzzer's parser paths only.
COPIED = {
    "unsupported_32bit_implicit_le.dcm": "rtdose_1frame.dcm",  # implicit VR little endian
    "unsupported_32bit_explicit_be.dcm": "rtdose_expb_1frame.dcm",  # explicit VR big endian
    "unsupported_32bit_rle.dcm": "rtdose_rle_1frame.dcm",  # RLE lossless
    "unsupported_32bit_multiframe.dcm": "rtdose.dcm",  # 15 frames
    "seed_deflated.dcm": "image_dfl.dcm",  # deflated explicit VR little endian
    "seed_rle_mr.dcm": "MR_small_RLE.dcm",  # RLE lossless, 16-bit
    "seed_j2k_lossless.dcm": "MR_small_jp2klossless.dcm",  # JPEG 2000 lossless
}


def ct_slice(series_uid: str, k: int) -> bytes:
    """One 4 x 4 CT slice at z = 2.5 k mm, explicit VR little endian."""
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
    meta.MediaStorageSOPInstanceUID = generate_uid(entropy_srcs=[series_uid, str(k)])
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID = meta.MediaStorageSOPClassUID
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.Modality = "CT"
    ds.SeriesInstanceUID = series_uid
    ds.SeriesDescription = "fuzz seed"
    ds.InstanceNumber = k + 1
    ds.ImagePositionPatient = [-10.0, -20.0, 2.5 * k]
    ds.ImageOrientationPatient = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    ds.PixelSpacing = [0.5, 0.75]
    ds.SliceThickness = 2.5
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows = 4
    ds.Columns = 4
    ds.BitsAllocated = 16
    ds.BitsStored = 12
    ds.HighBit = 11
    ds.PixelRepresentation = 0
    ds.RescaleSlope = 1
    ds.RescaleIntercept = -1024
    ds.PixelData = (np.arange(16, dtype=np.uint16) * 100 + k).tobytes()
    out = io.BytesIO()
    ds.save_as(out, enforce_file_format=True)
    return out.getvalue()


def main(folder: str) -> None:
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    for name, source in COPIED.items():
        shutil.copyfile(get_testdata_file(source), out / name)
    uid = "1.2.826.0.1.3680043.8.498.1"  # fixed, so the seeds are reproducible
    # The slices in the order 2, 0, 1: the reader sorts them by position.
    series = SEPARATOR.join(ct_slice(uid, k) for k in (2, 0, 1))
    (out / "seed_series3.dcm").write_bytes(series)
    (out / "seed_slice.dcm").write_bytes(ct_slice(uid, 0))


if __name__ == "__main__":
    main(sys.argv[1])

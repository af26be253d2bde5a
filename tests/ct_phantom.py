"""A small asymmetric head phantom for the CT tests, and writers of it in every format.

Index ``(i, j, k)`` of :func:`head` sits at LPS ``(1.5 i, 1.5 j, 1.5 k)`` mm: skin ellipsoid,
skull shell, a jaw block anterior-inferior, a bone knob on the patient's left (so any mirror
shows) and, optionally, a spine column posterior down to the volume's floor.
"""

import gzip

import numpy as np

VOXEL = 1.5
SHAPE_ZYX = (80, 76, 64)
CENTRE_LPS = np.array([47.0, 56.0, 66.0])
AIR, SOFT, BONE = 0, 1000, 1600  # scanner units (HU + 1000)


def head(spine=False, hu=False):
    """The phantom, int16 ``[k, j, i]``; ``hu``: Hounsfield units (air -1000)."""
    k, j, i = np.indices(SHAPE_ZYX, dtype=float) * VOXEL
    x, y, z = i - CENTRE_LPS[0], j - CENTRE_LPS[1], k - CENTRE_LPS[2]
    r_skull = np.sqrt((x / 36) ** 2 + (y / 42) ** 2 + (z / 38) ** 2)
    r_skin = np.sqrt((x / 44) ** 2 + (y / 50) ** 2 + (z / 46) ** 2)
    jaw = (np.abs(x) < 12) & (y > -40) & (y < -20) & (z > -58) & (z < -25)
    jaw_skin = (np.abs(x) < 17) & (y > -45) & (y < -15) & (z > -63) & (z < -20)
    knob = (x > 30) & (x < 40) & (np.abs(y) < 5) & (z > 0) & (z < 10)
    data = np.full(SHAPE_ZYX, AIR, np.int16)
    data[(r_skin < 1) | jaw_skin] = SOFT
    bone = ((r_skull > 0.8) & (r_skull < 1)) | jaw | knob
    if spine:
        column = (np.abs(x) < 8) & (y > 5) & (y < 20) & (z < -30)
        data[(np.abs(x) < 12) & (y > 0) & (y < 25) & (z < -25)] = SOFT
        bone |= column
    data[bone] = BONE
    return data - 1000 if hu else data


def write_nrrd(
    path,
    data,
    space="left-posterior-superior",
    directions=None,
    origin=(0, 0, 0),
    gz=False,
    extra="",
):
    """An attached NRRD (int16) with ``space directions`` (default 1.5 mm identity)."""
    if directions is None:
        directions = np.eye(3) * VOXEL
    dirs = " ".join("(" + ",".join(f"{v:g}" for v in col) + ")" for col in directions)
    header = (
        "NRRD0004\ntype: short\ndimension: 3\n"
        + (f"space: {space}\n" if space else "")
        + f"sizes: {data.shape[2]} {data.shape[1]} {data.shape[0]}\n"
        + f"space directions: {dirs}\n"
        + "space origin: ("
        + ",".join(f"{v:g}" for v in origin)
        + ")\n"
        + f"endian: little\nencoding: {'gzip' if gz else 'raw'}\n"
        + extra
    )
    payload = data.astype("<i2").tobytes()
    path.write_bytes(header.encode() + b"\n" + (gzip.compress(payload) if gz else payload))
    return path


def write_metaimage(path, data, extra, compressed=None):
    """A ``.mha`` (int16, little-endian); ``extra`` holds orientation lines."""
    payload = data.astype("<i2").tobytes() if compressed is None else compressed
    header = (
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
        + f"ElementSpacing = {VOXEL} {VOXEL} {VOXEL}\n"
        + f"DimSize = {data.shape[2]} {data.shape[1]} {data.shape[0]}\n"
        + extra
        + ("CompressedData = True\n" if compressed is not None else "")
        + "ElementType = MET_SHORT\nElementDataFile = LOCAL\n"
    )
    path.write_bytes(header.encode() + payload)
    return path


def write_dicom(folder, data_hu, iop=(1, 0, 0, 0, 1, 0), position=lambda k: (0.0, 0.0, 1.5 * k)):
    """A CT series in HU (stored + 1024), one file per slice, written out of order."""
    import pydicom
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, generate_uid

    folder.mkdir()
    series = generate_uid()
    order = np.random.default_rng(0).permutation(data_hu.shape[0])
    for n, k in enumerate(order):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CTImageStorage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID = CTImageStorage
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.SeriesInstanceUID = series
        ds.Modality = "CT"
        ds.Rows, ds.Columns = data_hu.shape[1], data_hu.shape[2]
        ds.PixelSpacing = [VOXEL, VOXEL]
        ds.ImageOrientationPatient = list(iop)
        ds.ImagePositionPatient = [float(v) for v in position(int(k))]
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
        ds.RescaleSlope, ds.RescaleIntercept = 1, -1024
        ds.PixelData = (data_hu[k].astype(np.int32) + 1024).astype("<u2").tobytes()
        pydicom.dcmwrite(folder / f"img{n:03d}.dcm", ds, enforce_file_format=True)
    return folder

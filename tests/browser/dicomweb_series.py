#!/usr/bin/python3
"""A generated CT series with a marker, written uncompressed and re-encoded
with Debian's encoders, for tests/browser/dicomweb.test.mjs and
bench/dicomweb/browser.mjs (which store them in Orthanc).

  dicomweb_series.py OUT COLUMNS ROWS SLICES [KIND ...]

KIND: jpeg-lossless (DCMTK dcmcjpeg +e1: process 14 SV1, .4.70),
j2k-lossless (OpenJPEG opj_compress, reversible 5/3: .4.90), htj2k-lossless
(OpenJPH ojph_compress -reversible: .4.201). Kinds whose tool is missing
are left out (the manifest says which).

OUT/original/ holds the uncompressed series (explicit VR little endian),
OUT/KIND/ the same slices re-encoded, each a series of its own (Series
Instance UID and SOP Instance UIDs of their own, one study); OUT/stored.raw
the stored values (uint16 LE, x fastest, then rows, then files in
order); OUT/manifest.json the series UIDs, sizes and the marker.

The volume: a CT-like ellipsoid body (12-bit, Rescale Intercept -1024) with
a deterministic 0..15 texture so that lossless coders have low bits to keep,
and a bright marker box in the right-anterior-superior corner (columns run
right to left, rows anterior to posterior, slices inferior to superior).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import pydicom
from pydicom._uid_dict import UID_dictionary
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.encaps import encapsulate
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

# pydicom 2.3 predates HTJ2K: its transfer syntax is made known to it.
UID_dictionary.setdefault('1.2.840.10008.1.2.4.201',
                          ('HTJ2KLossless', 'Transfer Syntax', '', '', 'HTJ2KLossless'))

out, cols, rows, slices = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
kinds = sys.argv[5:]
TOOLS = {'jpeg-lossless': 'dcmcjpeg', 'j2k-lossless': 'opj_compress', 'htj2k-lossless': 'ojph_compress'}
SYNTAX = {'original': ExplicitVRLittleEndian, 'jpeg-lossless': '1.2.840.10008.1.2.4.70',
          'j2k-lossless': '1.2.840.10008.1.2.4.90', 'htj2k-lossless': '1.2.840.10008.1.2.4.201'}
os.makedirs(out, exist_ok=True)
work = tempfile.mkdtemp()


def volume():
    z, y, x = np.meshgrid(np.arange(slices), np.arange(rows), np.arange(cols), indexing='ij')
    r = ((x - cols / 2) / (0.42 * cols)) ** 2 + ((y - rows / 2) / (0.36 * rows)) ** 2 + \
        ((z - slices / 2) / (0.48 * slices)) ** 2
    v = np.where(r < 1, 1024 + 40, 1024 - 1000).astype(np.int32)  # soft tissue in air (HU + 1024)
    v += np.where(r < 0.15, 700, 0)  # a bone-like core
    v += (x * 7 + y * 3 + z * 5) % 16  # low bits
    # The marker: columns 8%..20% (patient's right), rows 10%..22%
    # (anterior), slices 75%..90% (superior).
    marker = [int(0.08 * cols), int(0.20 * cols), int(0.10 * rows), int(0.22 * rows),
              int(0.75 * slices), int(0.90 * slices)]
    c0, c1, r0, r1, s0, s1 = marker
    v[s0:s1, r0:r1, c0:c1] = 3000
    return v.astype(np.uint16), marker


def write_original(folder, v, study, series):
    os.makedirs(folder, exist_ok=True)
    for k in range(slices):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = '1.2.840.10008.5.1.4.1.1.2'  # CT Image Storage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        d = Dataset()
        d.file_meta = meta
        d.is_little_endian, d.is_implicit_VR = True, False
        d.SOPClassUID, d.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
        d.Modality = 'CT'
        d.PatientName, d.PatientID = 'Web^Marker', 'dicomweb-%dx%dx%d' % (cols, rows, slices)
        d.StudyDescription, d.SeriesDescription = 'DICOMweb test', 'marker'
        d.StudyDate, d.SeriesNumber = '20261129', 1
        d.StudyInstanceUID, d.SeriesInstanceUID = study, series
        d.InstanceNumber = k + 1
        # LPS: columns run toward the patient's left (+x), rows toward posterior (+y).
        d.ImagePositionPatient = [-0.5 * cols * 0.8, -0.5 * rows * 0.8, -60.0 + 1.25 * k]
        d.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        d.PixelSpacing = [0.8, 0.8]
        d.SliceThickness = 1.25
        d.SamplesPerPixel, d.PhotometricInterpretation = 1, 'MONOCHROME2'
        d.Rows, d.Columns = rows, cols
        d.BitsAllocated, d.BitsStored, d.HighBit, d.PixelRepresentation = 16, 12, 11, 0
        d.RescaleIntercept, d.RescaleSlope = -1024, 1
        d.WindowCenter, d.WindowWidth = 40, 400
        d.PixelData = v[k].astype('<u2').tobytes()
        d.save_as(f'{folder}/slice_{k:04d}.dcm', write_like_original=False)


def encode(kind, src_folder, folder, series):
    os.makedirs(folder, exist_ok=True)
    for f in sorted(os.listdir(src_folder)):
        src, dst = f'{src_folder}/{f}', f'{folder}/{f}'
        if kind == 'jpeg-lossless':
            subprocess.run(['dcmcjpeg', '+e1', src, f'{work}/f.dcm'], check=True)
            d = pydicom.dcmread(f'{work}/f.dcm')
        else:
            d = pydicom.dcmread(src)
            a = d.pixel_array
            if kind == 'j2k-lossless':
                pgm, stream = f'{work}/f.pgm', f'{work}/f.j2k'
                with open(pgm, 'wb') as p:
                    p.write(b'P5\n%d %d\n%d\n' % (cols, rows, 4095))
                    p.write(a.astype('>u2').tobytes())
                subprocess.run(['opj_compress', '-i', pgm, '-o', stream], check=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            else:
                raw, stream = f'{work}/f.raw', f'{work}/f.j2c'
                a.astype('<u2').tofile(raw)
                subprocess.run(['ojph_compress', '-i', raw, '-o', stream, '-dims', '{%d,%d}' % (cols, rows),
                                '-num_comps', '1', '-signed', 'false', '-bit_depth', '12',
                                '-downsamp', '{1,1}', '-reversible', 'true'], check=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            d.file_meta.TransferSyntaxUID = SYNTAX[kind]
            d.is_little_endian, d.is_implicit_VR = True, False
            d.PixelData = encapsulate([open(stream, 'rb').read()])
            d['PixelData'].VR = 'OB'
            d['PixelData'].is_undefined_length = True
        d.SeriesInstanceUID = series
        d.SeriesDescription = 'marker ' + kind
        d.SeriesNumber = 2 + list(TOOLS).index(kind)
        d.SOPInstanceUID = generate_uid(None, [d.SOPInstanceUID, kind])
        d.file_meta.MediaStorageSOPInstanceUID = d.SOPInstanceUID
        d.save_as(dst, write_like_original=False)


v, marker = volume()
study = generate_uid()
manifest = {'columns': cols, 'rows': rows, 'slices': slices, 'study': study, 'marker': marker,
            'intercept': -1024, 'series': {}, 'missing': []}
series = generate_uid()
write_original(f'{out}/original', v, study, series)
v.astype('<u2').tofile(f'{out}/stored.raw')
manifest['series']['original'] = {'uid': series, 'syntax': SYNTAX['original'], 'folder': f'{out}/original'}
for kind in kinds:
    if not shutil.which(TOOLS[kind]):
        manifest['missing'].append(f'{kind} ({TOOLS[kind]} is not installed)')
        continue
    series = generate_uid()
    encode(kind, f'{out}/original', f'{out}/{kind}', series)
    manifest['series'][kind] = {'uid': series, 'syntax': SYNTAX[kind], 'folder': f'{out}/{kind}'}
with open(f'{out}/manifest.json', 'w') as f:
    json.dump(manifest, f, indent=1)
shutil.rmtree(work)

#!/usr/bin/python3
"""Compressed DICOM series for tests/browser/dicom-codecs.test.mjs, made from
our own uncompressed data with Debian's encoders, plus pydicom's greyscale
compressed test files; and the native CLI's reading of each.

  dicom_codec_series.py OUT TESSERA_CLI

OUT/manifest.json lists every series: its folder, transfer syntax, whether it
is lossless, and raw files of its stored values in file-name order (LE):
`original` (the uncompressed source, ours only) and `native` (the same files
decoded by the command-line tools of the libraries the CLI uses: DCMTK's
dcmdjpeg/dcmdjpls, OpenJPEG's opj_decompress for JPEG 2000, and for HTJ2K,
which the CLI refuses, OpenJPEG 2.5's opj_decompress too). For
each series the CLI converts the folder to NIfTI and the voxels are compared
with the uncompressed series' (ours) or with the command-line decode
(pydicom's), recorded in the manifest as `cli`.

The source is ch2 (mricron-data, a T1 head): 16 axial slices of 181x217, as
8-bit and as a 12-bit CT-like series (ch2 * 16 plus a deterministic 0..15
texture so that lossless coders have low bits to keep; Rescale Intercept
-1024).
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import time

import nibabel as nib
import numpy as np
import pydicom
from pydicom._uid_dict import UID_dictionary
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.encaps import encapsulate, encapsulate_extended, generate_pixel_data_frame
from pydicom.uid import generate_uid, ExplicitVRLittleEndian

# pydicom 2.3 predates HTJ2K: its transfer syntaxes are made known to it.
for _uid, _name in (('1.2.840.10008.1.2.4.201', 'HTJ2KLossless'),
                    ('1.2.840.10008.1.2.4.203', 'HTJ2K')):
    UID_dictionary.setdefault(_uid, (_name, 'Transfer Syntax', '', '', _name))

CH2 = '/usr/share/mricron/templates/ch2.nii.gz'
PYDICOM_FILES = '/usr/lib/python3/dist-packages/pydicom/data/test_files'
# pydicom's greyscale compressed test files (the colour ones are refused by
# both readers: one sample per pixel only).
PYDICOM_GREY = ['MR_small_jp2klossless.dcm', 'MR_small_jpeg_ls_lossless.dcm', 'JPEG2000.dcm',
                'JPEG2000-embedded-sequence-delimiter.dcm', '693_J2KI.dcm',
                'J2K_pixelrep_mismatch.dcm', 'JPEG-lossy.dcm', 'JPGExtended.dcm']
SLICES = range(78, 94)


def run(*args):
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def source_slices():
    a = np.asarray(nib.load(CH2).dataobj).astype(np.uint16)  # x, y, z (RAS)
    out = {}
    texture = (np.add.outer(np.arange(a.shape[0]) * 7, np.arange(a.shape[1]) * 3) % 16).astype(np.uint16)
    for bits in (8, 12):
        slices = []
        for z in SLICES:
            s = a[:, :, z].T[::-1, ::-1]  # rows: anterior→posterior, columns: right→left (LPS)
            slices.append(s.astype(np.uint8) if bits == 8 else (s * 16 + texture.T[::-1, ::-1]).astype(np.uint16))
        out[bits] = slices
    return out


def write_original(folder, slices, bits):
    os.makedirs(folder)
    series, study = generate_uid(), generate_uid()
    for k, s in enumerate(slices):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = '1.2.840.10008.5.1.4.1.1.2'  # CT Image Storage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        d = Dataset()
        d.file_meta = meta
        d.is_little_endian, d.is_implicit_VR = True, False
        d.SOPClassUID, d.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
        d.Modality = 'CT' if bits == 12 else 'MR'
        d.PatientName, d.PatientID = 'Codec^Test', 'codec'
        d.StudyInstanceUID, d.SeriesInstanceUID = study, series
        d.InstanceNumber = k + 1
        d.ImagePositionPatient = [90.0, 126.0, -72.0 + SLICES[k]]
        d.ImageOrientationPatient = [-1, 0, 0, 0, -1, 0]
        d.PixelSpacing = [1, 1]
        d.SliceThickness = 1
        d.SamplesPerPixel, d.PhotometricInterpretation = 1, 'MONOCHROME2'
        d.Rows, d.Columns = s.shape
        d.BitsAllocated = 8 if bits == 8 else 16
        d.BitsStored, d.HighBit, d.PixelRepresentation = bits, bits - 1, 0
        d.RescaleIntercept, d.RescaleSlope = (-1024 if bits == 12 else 0), 1
        d.PixelData = s.tobytes()
        d.save_as(f'{folder}/slice_{k:04d}.dcm', write_like_original=False)


def wrap(src, out, stream, uid):
    d = pydicom.dcmread(src)
    d.file_meta.TransferSyntaxUID = uid
    d.is_little_endian, d.is_implicit_VR = True, False
    d.PixelData = encapsulate([open(stream, 'rb').read()])
    d['PixelData'].VR = 'OB'
    d['PixelData'].is_undefined_length = True
    if uid.endswith(('.91', '.203')):
        d.LossyImageCompression = '01'
    d.save_as(out, write_like_original=False)


def encode(kind, src_folder, folder, work):
    os.makedirs(folder)
    for f in sorted(os.listdir(src_folder)):
        src, out = f'{src_folder}/{f}', f'{folder}/{f}'
        if kind in JPEG_TOOLS:
            run(*JPEG_TOOLS[kind], src, out)
            continue
        d = pydicom.dcmread(src)
        a = d.pixel_array
        rows, cols = a.shape
        if kind.startswith('j2k'):
            pgm = f'{work}/f.pgm'
            with open(pgm, 'wb') as p:
                p.write(b'P5\n%d %d\n%d\n' % (cols, rows, 2 ** d.BitsStored - 1))
                p.write(a.astype('>u2' if d.BitsStored > 8 else 'u1').tobytes())
            stream = f'{work}/f.j2k'
            run('opj_compress', '-i', pgm, '-o', stream, *(['-r', '12'] if kind == 'j2k-lossy' else []))
            wrap(src, out, stream, '1.2.840.10008.1.2.4.91' if kind == 'j2k-lossy' else '1.2.840.10008.1.2.4.90')
        else:
            raw = f'{work}/f.raw'
            a.astype('<u2' if d.BitsStored > 8 else 'u1').tofile(raw)
            stream = f'{work}/f.j2c'
            args = ['ojph_compress', '-i', raw, '-o', stream, '-dims', '{%d,%d}' % (cols, rows),
                    '-num_comps', '1', '-signed', 'false', '-bit_depth', str(d.BitsStored),
                    '-downsamp', '{1,1}']
            args += ['-reversible', 'true'] if kind == 'htj2k-lossless' else ['-qstep', '0.002']
            run(*args)
            wrap(src, out, stream, '1.2.840.10008.1.2.4.201' if kind == 'htj2k-lossless' else '1.2.840.10008.1.2.4.203')


JPEG_TOOLS = {
    'jpeg-baseline': ['dcmcjpeg', '+eb', '+q', '90'],
    'jpeg-extended-12bit': ['dcmcjpeg', '+ee', '+q', '90'],
    # process 14 with predictor 6, fragments of 4 KB (several per frame)
    'jpeg-lossless-p14': ['dcmcjpeg', '+el', '+sv', '6', '+fs', '4'],
    'jpeg-lossless-sv1': ['dcmcjpeg', '+e1'],
    'jpegls-lossless': ['dcmcjpls', '+el'],
    'jpegls-near-lossless': ['dcmcjpls', '+en', '+md', '2'],
}
SERIES = [  # kind, bits of the source, lossless
    ('jpeg-baseline', 8, False), ('jpeg-extended-12bit', 12, False),
    ('jpeg-lossless-p14', 12, True), ('jpeg-lossless-sv1', 12, True),
    ('jpegls-lossless', 12, True), ('jpegls-near-lossless', 12, False),
    ('j2k-lossless', 12, True), ('j2k-lossy', 12, False),
    ('htj2k-lossless', 12, True), ('htj2k-lossy', 12, False),
]


def stored(path):
    d = pydicom.dcmread(path)
    a = d.pixel_array
    return a.astype('<u2' if d.BitsAllocated == 16 and d.PixelRepresentation == 0
                    else '<i2' if d.BitsAllocated == 16 else 'u1')


def native_decode(path, work):
    """The stored values as the command-line tools of the CLI's libraries decode them."""
    d = pydicom.dcmread(path)
    ts = str(d.file_meta.TransferSyntaxUID)
    out = f'{work}/dec.dcm'
    if ts in ('1.2.840.10008.1.2.4.80', '1.2.840.10008.1.2.4.81'):
        run('dcmdjpls', path, out)
        return stored(out)
    if ts.startswith('1.2.840.10008.1.2.4.5') or ts.startswith('1.2.840.10008.1.2.4.7'):
        run('dcmdjpeg', path, out)
        return stored(out)
    frame = next(generate_pixel_data_frame(d.PixelData))
    open(f'{work}/f.j2k', 'wb').write(frame)
    for old in glob.glob(f'{work}/f*.pgx'):
        os.remove(old)
    run('opj_decompress', '-i', f'{work}/f.j2k', '-o', f'{work}/f.pgx')
    raw = open(sorted(glob.glob(f'{work}/f*.pgx'))[0], 'rb').read()
    header, data = raw.split(b'\n', 1)
    parts = header.split()
    signed = parts[2].startswith(b'-')
    a = np.frombuffer(data[:int(parts[-1]) * int(parts[-2]) * (1 if int(parts[-3]) <= 8 else 2)],
                      dtype=('>' if parts[1] == b'ML' else '<') + ('i' if signed else 'u') +
                      ('1' if int(parts[-3]) <= 8 else '2'))
    a = a.reshape(int(parts[-1]), int(parts[-2]))
    # As the DICOM header says the values are stored.
    return a.astype('<u2' if d.BitsAllocated == 16 and d.PixelRepresentation == 0
                    else '<i2' if d.BitsAllocated == 16 else 'u1')


def raw_of(arrays, path):
    with open(path, 'wb') as f:
        for a in arrays:
            f.write(a.tobytes())


def psnr(a, b, peak):
    err = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return None if err == 0 else float(10 * np.log10(peak * peak / err))  # None: identical (JSON has no inf)


def cli_volume(cli, target, work):
    out = f'{work}/cli.nii'
    if os.path.exists(out):
        os.remove(out)
    t = time.time()
    p = subprocess.run([cli, 'convert', target, out], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ms = (time.time() - t) * 1000
    if p.returncode != 0:
        return None, ms, (p.stderr.strip().splitlines() or ['exit %d' % p.returncode])[-1]
    return np.asarray(nib.load(out).get_fdata()), ms, ''


def compare_cli(entry, cli, reference, work, peak):
    v, ms, err = cli_volume(cli, entry['folder'] + '/' + sorted(os.listdir(entry['folder']))[0], work)
    if v is None:
        return {'ok': False, 'error': err, 'ms': round(ms)}
    if v.shape != reference.shape:
        return {'ok': False, 'error': f'shape {v.shape} vs {reference.shape}', 'ms': round(ms)}
    diff = int(np.count_nonzero(v != reference))
    return {'ok': True, 'differing': diff, 'voxels': int(v.size), 'psnr': psnr(v, reference, peak),
            'maxdiff': float(np.max(np.abs(v - reference))), 'ms': round(ms)}


def pydicom_cli(entry, cli, native, d, work):
    """The CLI's volume of a single pydicom file against the command-line
    decode, rescaled; the CLI's volume is in RAS order, so the in-plane
    flips are tried (the geometry is other tests' business)."""
    v, ms, err = cli_volume(cli, entry['folder'] + '/' + entry['file'], work)
    if v is None:
        return {'ok': False, 'error': err, 'ms': round(ms)}
    want = native.astype(np.float64) * float(getattr(d, 'RescaleSlope', 1)) + float(getattr(d, 'RescaleIntercept', 0))
    got = np.squeeze(v)
    best = None
    for t in (got, got.T):
        for fx in (False, True):
            for fy in (False, True):
                c = t[::-1] if fx else t
                c = c[:, ::-1] if fy else c
                if c.shape == want.shape:
                    n = int(np.count_nonzero(c != want))
                    best = n if best is None else min(best, n)
    if best is None:
        return {'ok': False, 'error': f'shape {got.shape} vs {want.shape}', 'ms': round(ms)}
    return {'ok': True, 'differing': best, 'voxels': int(want.size), 'ms': round(ms)}


def make_bad(out, series):
    """One slice of several series made bad: its codestream cut in half (the
    fragment's length still right), or Rows not what the stream holds."""
    folder = f'{out}/bad'
    os.makedirs(folder)
    bad = []
    for kind in ('htj2k-lossless', 'j2k-lossless', 'jpegls-lossless', 'jpeg-lossless-sv1', 'jpeg-baseline'):
        entry = next(e for e in series if e['kind'] == kind)
        src = f"{entry['folder']}/{entry['files'][4]}"
        for how in ('truncated', 'rows'):
            d = pydicom.dcmread(src)
            frame = next(generate_pixel_data_frame(d.PixelData))
            if how == 'truncated':
                d.PixelData = encapsulate([frame[:len(frame) // 2]])
            else:
                d.PixelData = encapsulate([frame])
                d.Rows = d.Rows - 16
            d['PixelData'].is_undefined_length = True
            name = f'{kind}-{how}.dcm'
            d.save_as(f'{folder}/{name}', write_like_original=False)
            bad.append({'file': name, 'kind': kind, 'how': how})
    return bad


def make_multiframe(out, series):
    """The first three JPEG-LS slices as one 3-frame file, in each layout of
    PS3.5 A.4: a basic offset table with three fragments per frame, no table
    with two fragments per frame (found by their start markers), no table
    with one fragment per frame, and an extended offset table."""
    folder = f'{out}/multiframe'
    os.makedirs(folder)
    entry = next(e for e in series if e['kind'] == 'jpegls-lossless')
    frames = [next(generate_pixel_data_frame(pydicom.dcmread(f"{entry['folder']}/{f}").PixelData))
              for f in entry['files'][:3]]
    made = []
    for name, pixels, eot in (
            ('bot-3-fragments-per-frame.dcm', encapsulate(frames, fragments_per_frame=3, has_bot=True), None),
            ('no-bot-2-fragments-per-frame.dcm', encapsulate(frames, fragments_per_frame=2, has_bot=False), None),
            ('no-bot-1-fragment-per-frame.dcm', encapsulate(frames, fragments_per_frame=1, has_bot=False), None),
            ('extended-offset-table.dcm', None, encapsulate_extended(frames))):
        d = pydicom.dcmread(f"{entry['folder']}/{entry['files'][0]}")
        d.NumberOfFrames = 3
        d.PixelData = pixels if eot is None else eot[0]
        d['PixelData'].VR = 'OB'
        d['PixelData'].is_undefined_length = True
        if eot is not None:
            d.ExtendedOffsetTable, d.ExtendedOffsetTableLengths = eot[1], eot[2]
            d['ExtendedOffsetTable'].VR = d['ExtendedOffsetTableLengths'].VR = 'OV'
        d.save_as(f'{folder}/{name}', write_like_original=False)
        made.append(name)
    return {'folder': folder, 'files': made, 'frames': 3, 'bits': 12, 'original': entry['original']}


def main():
    out, cli = sys.argv[1], sys.argv[2]
    work = f'{out}/work'
    os.makedirs(work, exist_ok=True)
    t0 = time.time()
    src = source_slices()
    manifest = {'series': [], 'pydicom': []}
    originals = {}
    for bits in (8, 12):
        folder = f'{out}/original-{bits}bit'
        write_original(folder, src[bits], bits)
        raw_of(src[bits], f'{folder}.raw')
        originals[bits] = folder
    ref = {bits: cli_volume(cli, originals[bits] + '/slice_0000.dcm', work)[0] for bits in (8, 12)}
    for kind, bits, lossless in SERIES:
        folder = f'{out}/{kind}'
        encode(kind, originals[bits], folder, work)
        files = sorted(os.listdir(folder))
        ts = str(pydicom.dcmread(f'{folder}/{files[0]}', stop_before_pixels=True).file_meta.TransferSyntaxUID)
        raw_of([native_decode(f'{folder}/{f}', work) for f in files], f'{folder}.native.raw')
        entry = {'kind': kind, 'folder': folder, 'files': files, 'syntax': ts, 'lossless': lossless,
                 'bits': bits, 'original': f'{originals[bits]}.raw', 'native': f'{folder}.native.raw',
                 'originalFolder': originals[bits],
                 'bytes': sum(os.path.getsize(f'{folder}/{f}') for f in files)}
        entry['cli'] = compare_cli(entry, cli, ref[bits], work, 255 if bits == 8 else 4095)
        manifest['series'].append(entry)
    for name in PYDICOM_GREY:
        path = f'{PYDICOM_FILES}/{name}'
        if not os.path.exists(path):
            continue
        folder = f'{out}/pydicom-{name[:-4]}'
        os.makedirs(folder)
        shutil.copy(path, folder)
        d = pydicom.dcmread(path)
        entry = {'kind': name, 'folder': folder, 'file': name, 'files': [name],
                 'syntax': str(d.file_meta.TransferSyntaxUID), 'native': f'{folder}.native.raw',
                 'bits': int(d.BitsStored), 'lossless': None}
        try:
            native = native_decode(path, work)
        except subprocess.CalledProcessError as e:
            entry['native'] = None
            entry['nativeError'] = (e.stderr or b'').decode(errors='replace').strip().splitlines()[-1:] or [str(e)]
            v, ms, err = cli_volume(cli, f'{folder}/{name}', work)
            entry['cli'] = {'ok': False, 'ms': round(ms), 'error': (err or 'read (%s voxels), but no command-line decode to compare with' % (v.size if v is not None else 0))}
            manifest['pydicom'].append(entry)
            continue
        raw_of([native], f'{folder}.native.raw')
        # The command-line tools are the reference (pydicom 2.3 here has no
        # JPEG or JPEG 2000 handler).
        entry['cli'] = pydicom_cli(entry, cli, native, d, work)
        manifest['pydicom'].append(entry)
    manifest['bad'] = make_bad(out, manifest['series'])
    manifest['multiframe'] = make_multiframe(out, manifest['series'])
    manifest['seconds'] = round(time.time() - t0, 1)
    json.dump(manifest, open(f'{out}/manifest.json', 'w'), indent=1)


if __name__ == '__main__':
    main()

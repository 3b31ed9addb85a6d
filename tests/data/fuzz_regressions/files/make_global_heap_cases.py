#!/usr/bin/python3
"""Writes the hand-made reproducers of tests/data/fuzz_regressions/files/: files as an older skinlab
wrote them (variable-length strings, whose data live in HDF5's global heap) with that heap
damaged so that libhdf5 1.10.8 crashes (SIGSEGV) on reading a string: the global heap
collection's size set to 16 bytes. A reader of this build must refuse each of them by its
format_version or by the string's type, before it reads any string data.

    /usr/bin/python3 tests/data/fuzz_regressions/files/make_global_heap_cases.py

(python3-h5py; run from anywhere, writes beside this script.)"""
import os
import struct

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def damage_global_heap(path):
    """Sets the size of the file's first global heap collection ('GCOL') to 16 bytes."""
    data = bytearray(open(path, 'rb').read())
    at = data.find(b'GCOL')
    assert at >= 0, path
    data[at + 8:at + 16] = struct.pack('<Q', 16)
    open(path, 'wb').write(bytes(data))


def dataset_file(path, version):
    with h5py.File(path, 'w') as f:
        f.attrs.create('format_version', np.int64(version))
        f.attrs['skinlab_git_commit'] = '0123abcd'  # h5py writes str as variable-length
        f.attrs['preparation'] = 'preprocess: {}\n'
        f.create_dataset('character_names', data=['alpha', 'beta'], dtype=h5py.string_dtype())
    damage_global_heap(path)


def parameters_file(path, version):
    with h5py.File(path, 'w') as f:
        f.attrs['format'] = 'skinlab-parameters'
        f.attrs.create('format_version', np.int64(version))
        f.attrs['model'] = 'heterskinnet'
        f.attrs['distance'] = 'euclidean'
        f.attrs['source'] = 'made by hand'
        f.attrs['architecture'] = '{"top_k": 2}'
        f.create_dataset('parameters/a.weight', data=np.ones((2, 3), np.float32))
    damage_global_heap(path)


def predictions_file(path):
    with h5py.File(path, 'w') as f:
        f.attrs['distance'] = 'euclidean'
        f.attrs['split'] = 'random'
        f.attrs.create('epoch', np.int64(3))
        f.create_dataset('character_names', data=['alpha'], dtype=h5py.string_dtype())
    damage_global_heap(path)


for target in ('dataset', 'parameters', 'predictions'):
    os.makedirs(os.path.join(HERE, target), exist_ok=True)
dataset_file(os.path.join(HERE, 'dataset', 'format2-vlen-damaged-global-heap.h5'), 2)
dataset_file(os.path.join(HERE, 'dataset', 'format3-vlen-damaged-global-heap.h5'), 3)
parameters_file(os.path.join(HERE, 'parameters', 'format1-vlen-damaged-global-heap.h5'), 1)
parameters_file(os.path.join(HERE, 'parameters', 'format2-vlen-damaged-global-heap.h5'), 2)
predictions_file(os.path.join(HERE, 'predictions', 'vlen-damaged-global-heap.h5'))

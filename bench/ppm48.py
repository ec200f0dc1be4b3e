"""Tachyon's 16-bit binary PPM (P6, maxval 65535) as a numpy array, for the bench scripts that compare its
images with vrmlray's: the pixels as stored (rows top first, big-endian 16-bit RGB)."""
import numpy as np


def read_ppm48(path):
    data = open(path, "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:  # magic, width, height, maxval; no comments in Tachyon's files
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    w, h, maxval = int(fields[1]), int(fields[2]), int(fields[3])
    assert fields[0] == b"P6" and maxval == 65535, path
    return np.frombuffer(data, dtype=">u2", count=w * h * 3, offset=pos + 1).reshape(h, w, 3)


def write_ppm48(path, pixels):
    h, w = pixels.shape[:2]
    open(path, "wb").write(b"P6\n%d %d\n65535\n" % (w, h) + pixels.astype(">u2").tobytes())

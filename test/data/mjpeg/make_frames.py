#!/usr/bin/python3
"""Makes the MJPEG test frames of modules/capture/mjpeg_decode_test.cc from rendered dot images (the
recorded sequences of test/data/sequences, which the test compares the decoded frames with).

Each frame is a JPEG as a UVC camera sends it in MJPEG mode: baseline, YCbCr 4:2:2 (PIL's subsampling=1),
quality 85. `*_nodht.jpg` is the same frame with its Huffman tables (DHT segments) removed, as most UVC
cameras send it (the decoder must supply the standard tables). Run from the repository root:
    /usr/bin/python3 test/data/mjpeg/make_frames.py
"""
import pathlib

from PIL import Image

HERE = pathlib.Path(__file__).resolve().parent
SOURCES = {
    "puma_clean_640x480": HERE.parent / "sequences" / "puma_arc_clean" / "frame_000000.png",
    "puma_noisy_640x480": HERE.parent / "sequences" / "puma_arc_noisy" / "frame_000001.png",
}


def strip_dht(data: bytes) -> bytes:
    out = bytearray(data[:2])  # SOI
    i = 2
    while i < len(data):
        assert data[i] == 0xFF, "marker expected"
        marker = data[i + 1]
        if marker == 0xDA:  # start of scan: the rest is entropy-coded data and EOI
            out += data[i:]
            break
        length = int.from_bytes(data[i + 2:i + 4], "big")
        if marker != 0xC4:
            out += data[i:i + 2 + length]
        i += 2 + length
    return bytes(out)


def main() -> None:
    for name, source in SOURCES.items():
        grey = Image.open(source).convert("L")
        jpeg = HERE / f"{name}.jpg"
        grey.convert("RGB").save(jpeg, "JPEG", quality=85, subsampling=1)
        (HERE / f"{name}_nodht.jpg").write_bytes(strip_dht(jpeg.read_bytes()))


if __name__ == "__main__":
    main()

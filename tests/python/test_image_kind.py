"""atmos.image_kind and atmos.image_file_kind: an image's format by its first bytes, as the
library's atmos_image_kind and atmos_image_file_kind (atmos/image.h) tell it, the magic numbers
spelt out here independently of the library; and of the files the package itself writes. The
image functions that take a file name refuse what is not one."""
import pytest

import atmos


@pytest.mark.parametrize("head,kind", [
    (b"\x76\x2f\x31\x01\x02\x00\x00\x00", "OpenEXR"),
    (b"\x89PNG\r\n\x1a\n", "PNG"),
    (b"\xff\xd8\xff\xe0", "JPEG"),
    (b"PF\n64 48\n", "PFM"),
    (b"Pf 3 2\n", "PFM"),
    (b"PF\r\n", "PFM"),
    (b"PFX", None),           # "PF" without the whitespace atmos_read_pfm takes after it
    (b"\x89PNG\r\n\x1a", None),  # a PNG signature cut short
    (b"GIF89a", None),
    (b"", None),
])
def test_image_kind_of_bytes(head, kind):
    assert atmos.image_kind(head) == kind
    assert atmos.image_kind(bytearray(head)) == kind
    assert atmos.image_kind(memoryview(head)) == kind


def test_image_kind_refuses_what_is_not_bytes():
    with pytest.raises(TypeError, match="atmos: image_kind: expected bytes"):
        atmos.image_kind("PF\n")


def test_image_file_kind_of_written_files(tmp_path):
    img = atmos.render(atmos.Scene.default(), width=8, height=6)
    img.write_exr(tmp_path / "a.exr")
    img.write_pfm(tmp_path / "a.pfm")
    assert atmos.image_file_kind(tmp_path / "a.exr") == "OpenEXR"
    assert atmos.image_file_kind(str(tmp_path / "a.pfm")) == "PFM"
    (tmp_path / "short").write_bytes(b"PF")
    assert atmos.image_file_kind(tmp_path / "short") is None
    assert atmos.image_file_kind(tmp_path / "missing.exr") is None
    with open(tmp_path / "a.exr", "rb") as f:
        assert atmos.image_kind(f.read(8)) == "OpenEXR"


def test_a_file_name_that_is_not_one_is_a_type_error(tmp_path):
    """None was taken as the file "None" (read_exr: "None: cannot open")."""
    img = atmos.render(atmos.Scene.default(), width=4, height=3)
    for call, where in ((lambda: atmos.read_exr(None), "read_exr"), (lambda: img.write_exr(None), "Image.write_exr"),
                        (lambda: img.write_pfm(3), "Image.write_pfm"), (lambda: atmos.image_file_kind(None), "image_file_kind")):
        with pytest.raises(TypeError, match=f"atmos: {where}: expected a file name"):
            call()
    img.write_exr(str(tmp_path / "b.EXR").encode())
    assert atmos.read_exr(tmp_path / "b.EXR").shape == (3, 4, 4)


def test_a_file_name_with_a_nul_byte_is_refused(tmp_path):
    """The library reads a name up to its NUL: "x\\0.exr" passed the suffix's check and wrote "x"."""
    img = atmos.render(atmos.Scene.default(), width=4, height=3)
    with pytest.raises(ValueError, match="atmos: Image.write_exr: a file name with a NUL byte"):
        img.write_exr(str(tmp_path / "x") + "\0.exr")
    assert not (tmp_path / "x").exists()

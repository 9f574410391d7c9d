"""tempera.app.exemplar_kit: finding the bundled exemplar kit (no Blender)."""
import pytest

from tempera.app import exemplar_kit as kit


def make_kit(folder, variant):
    (folder / variant / "guides").mkdir(parents=True)
    (folder / variant / "style.png").write_bytes(b"png")
    (folder / variant / "guides" / "manifest.json").write_text("{}")


def test_kit_paths(tmp_path):
    make_kit(tmp_path, "sphere_on_table")
    style, guides = kit.kit_exemplar(kit_dir=tmp_path)
    assert style == tmp_path / "sphere_on_table" / "style.png"
    assert guides == tmp_path / "sphere_on_table" / "guides"


def test_missing_kit_names_what_is_there_and_how_to_build_it(tmp_path):
    make_kit(tmp_path, "sphere_and_box")
    with pytest.raises(FileNotFoundError, match=r"'sphere_on_table'.*kits present: sphere_and_box.*make addon-zip"):
        kit.kit_exemplar(kit_dir=tmp_path)
    with pytest.raises(FileNotFoundError, match="kits present: none"):
        kit.kit_exemplar(kit_dir=tmp_path / "nowhere")


def test_incomplete_kit_is_missing(tmp_path):
    make_kit(tmp_path, "sphere_on_table")
    (tmp_path / "sphere_on_table" / "guides" / "manifest.json").unlink()
    with pytest.raises(FileNotFoundError):
        kit.kit_exemplar(kit_dir=tmp_path)


def test_the_kit_is_the_packages_kit_folder():
    """make_addon_zip packs the kit as tempera/kit; the extension points KIT_DIR beside itself."""
    import os
    from pathlib import Path

    import tempera

    if not os.environ.get("TEMPERA_KIT_DIR"):
        assert kit.KIT_DIR == Path(tempera.__file__).resolve().parent / "kit"

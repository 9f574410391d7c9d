from tempera.app import settings


def test_default_is_odd_and_in_range():
    assert settings.PATCH_SIZE_MIN <= settings.PATCH_SIZE_DEFAULT <= settings.PATCH_SIZE_MAX
    assert settings.PATCH_SIZE_DEFAULT % 2 == 1
    assert settings.PATCH_SIZE_MIN % 2 == 1 and settings.PATCH_SIZE_MAX % 2 == 1


def test_odd_patch_size():
    assert [settings.odd_patch_size(n) for n in range(0, 18)] == (
        [3, 3, 3, 3, 5, 5, 7, 7, 9, 9, 11, 11, 13, 13, 15, 15, 15, 15]
    )

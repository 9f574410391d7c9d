import pytest

from tempera.app.frames import parse_frames


def test_ranges_lists_and_single_frames():
    assert parse_frames("1-4") == [1, 2, 3, 4]
    assert parse_frames("7") == [7]
    assert parse_frames("1-3, 10,2") == [1, 2, 3, 10]


@pytest.mark.parametrize("text, message", [("3-1", "ends before it starts"), ("a-b", "cannot read 'a-b'"),
                                           ("1,,2", "empty part")])
def test_bad_ranges_name_the_problem(text, message):
    with pytest.raises(ValueError, match=message):
        parse_frames(text)

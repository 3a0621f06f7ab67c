import pytest

#: a small box (about 250 grains) so a packing takes well under a second
SMALL = {"width": 0.02, "height": 0.04}


@pytest.fixture
def small():
    return dict(SMALL)

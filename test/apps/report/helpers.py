"""Report pages read back with the standard library's HTML parser, and what they are made of."""

from __future__ import annotations

import base64
import functools
import io
from dataclasses import dataclass, field
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
from PIL import Image

from lumpbeam_ros.base.interface import TIP_LOAD, TIP_POSE
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.diagnose.measurement import make_record
from lumpbeam_ros.core.diagnose.workflow import Diagnosis, diagnose
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, load_messages, simulate_experiment

#: An epoch offset, s, as a real recording's header stamps carry.
T0 = 1_700_000_000.0

#: Elements without an end tag.
VOID = frozenset({'meta', 'link', 'img', 'br', 'hr', 'input'})
#: The blocks a report's body is made of.
BLOCKS = frozenset({'h1', 'h2', 'p', 'table', 'figure'})
DATA_PNG = 'data:image/png;base64,'


@dataclass
class Page:
    """What a report page shows.

    Attributes:
        title: The ``<title>``.
        h1: First-level headings.
        h2: Section headings.
        paragraphs: ``(text, class)`` of each paragraph.
        tables: Each table's rows of cell texts, its header row first.
        images: ``(alt, decoded PNG bytes)`` of each image.
        captions: The figure captions.
        order: The body's blocks, by tag, in order.
        links: Every ``src`` and ``href``.
    """

    title: str = ''
    h1: list[str] = field(default_factory=list)
    h2: list[str] = field(default_factory=list)
    paragraphs: list[tuple[str, str | None]] = field(default_factory=list)
    tables: list[list[list[str]]] = field(default_factory=list)
    images: list[tuple[str, bytes]] = field(default_factory=list)
    captions: list[str] = field(default_factory=list)
    order: list[str] = field(default_factory=list)
    links: list[str] = field(default_factory=list)

    def table_dict(self, index: int) -> dict[str, list[str]]:
        """A table's rows (header left out) keyed by their first cell."""
        return {row[0]: row[1:] for row in self.tables[index][1:]}


class _Reader(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.page = Page()
        self.open: list[str] = []
        self.text: list[str] = []
        self.attrs: dict[str, str | None] = {}

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        attributes = dict(attrs)
        for key in ('src', 'href'):
            if attributes.get(key) is not None:
                self.page.links.append(str(attributes[key]))
        if tag in BLOCKS and self.open[-1:] == ['body']:
            self.page.order.append(tag)
        if tag == 'table':
            self.page.tables.append([])
        elif tag == 'tr':
            self.page.tables[-1].append([])
        elif tag == 'img':
            src = str(attributes['src'])
            assert src.startswith(DATA_PNG), src[:40]
            data = base64.b64decode(src[len(DATA_PNG) :], validate=True)
            self.page.images.append((str(attributes['alt']), data))
        if tag not in VOID:
            self.open.append(tag)
            self.text, self.attrs = [], attributes

    def handle_endtag(self, tag: str) -> None:
        assert self.open and self.open[-1] == tag, f'</{tag}> closes {self.open[-1:]}'
        self.open.pop()
        text = ''.join(self.text)
        if tag == 'title':
            self.page.title = text
        elif tag in ('h1', 'h2'):
            getattr(self.page, tag).append(text)
        elif tag == 'p':
            self.page.paragraphs.append((text, self.attrs.get('class')))
        elif tag in ('td', 'th'):
            self.page.tables[-1][-1].append(text)
        elif tag == 'figcaption':
            self.page.captions.append(text)

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def parse_page(text: str) -> Page:
    """Parses a report page; every element must be closed in order.

    Raises:
        AssertionError: A misnested or unclosed element, or an image that is not a PNG data URI.
    """
    assert text.startswith('<!DOCTYPE html>\n')
    reader = _Reader()
    reader.feed(text)
    reader.close()
    assert reader.open == [], f'unclosed: {reader.open}'
    return reader.page


@functools.cache
def tiny_png() -> bytes:
    """A 3 x 2 PNG written by Pillow (not by the code under test)."""
    buffer = io.BytesIO()
    Image.new('RGB', (3, 2), (200, 30, 30)).save(buffer, format='PNG')
    return buffer.getvalue()


def write_epoch_drop(path: Path, duration_s: float = 5.0, noise_m: float = 20e-6) -> None:
    """The configured beam's drop test as a bag stamped from :data:`T0` (a real clock).

    The synthetic bags start at 0 s; a recorded bag's stamps are epoch seconds, which is what
    a report must print without rounding them away.
    """
    beam, drop = load_beam_config()
    measured, _ = simulate_experiment(beam, drop, SynthOptions(duration_s=duration_s))
    noise = noise_m * np.random.default_rng(5).standard_normal(len(measured))
    with BagWriter(path) as bag:
        for stamp, load in load_messages(drop, duration_s):
            bag.write_float(TIP_LOAD, T0 + stamp, load)
        for i, t in enumerate(measured.t):
            bag.write_pose(
                TIP_POSE, T0 + t, measured.x[i], measured.z[i] + noise[i], measured.pitch[i]
            )


def late_diagnosis() -> Diagnosis:
    """A short ring-down whose camera is 15 ms late, with 20 um of noise, diagnosed."""
    beam, drop = load_beam_config()
    m, _ = simulate_experiment(
        beam, drop, SynthOptions(duration_s=4.5, effects={'sensor_latency': 0.015})
    )
    rng = np.random.default_rng(3)
    noise = 20e-6 * rng.standard_normal((2, len(m)))
    record = make_record(m.t, m.z + noise[0], m.pitch + noise[1], drop.load_kg, [(2.0, 0.0)])
    return diagnose(record, beam)

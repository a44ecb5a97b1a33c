"""Edge profiles' plot images: drawn, found and removed so that each edge shows its own plot.

An edge record names its plot image (``edge.plot``), and Blender names are not identities: a
duplicated object (Shift+D) shares its edges' images with the original, and an object appended
from another file brings images that arrive renamed where this file has the same names. Each
image is therefore tagged with its edge's key (:func:`plot_key`), an image is taken for an edge
only where the tags agree, and an image is removed only where no other edge shows it.
"""

from __future__ import annotations

import hashlib

import bpy
import numpy as np

from ..vg_addon.formats import profile_plot
from ..vg_addon.formats.record_codec import exact_numbers
from . import records

PLOT_SIZE = (480, 240)
"""Width and height of a plot image, pixels."""

PREVIEW_SIZE = (256, 192)
"""Width and height of the plot's picture in the panel (its preview icon), pixels: about what the
sidebar shows, so its tick labels are drawn at the size they are seen."""

PLOT_KEY = "vg_edge_plot"
"""The image's custom property holding :func:`plot_key` of the edge it was drawn for."""

UNIT_KEY = "vg_plot_units"
"""The image's custom property holding the unit its axis names (see :func:`make_plot`)."""


def plot_key(edge) -> str:
    """What ties a plot to its edge: the edge's number and a digest of its exact numbers (set once,
    when the edge is measured; a duplicated object's edges keep them)."""
    digest = hashlib.sha256(edge.exact.encode("utf-8")).hexdigest()[:16]
    return f"{edge.number}:{digest}"


def make_plot(obj, edge):
    """The profile plot of ``edge`` as a packed image (saved inside the .blend), tagged with the
    edge's key: matplotlib's where Blender's Python has it, else the extension's NumPy drawing."""
    numbers = exact_numbers(edge)
    width, height = PLOT_SIZE
    units = records.unit_symbol(obj, bpy.context.scene)
    rgba = profile_plot.render_profile(
        numbers["arc_lengths"],
        numbers["angles"],
        width=width,
        height=height,
        units=units,
        title=f"{obj.name}, edge {edge.number}",
        pooled=numbers.get("pooled_angle"),
    )
    image = bpy.data.images.new(f"VG {obj.name} edge {edge.number}", width, height, alpha=True)
    # Blender's rows run bottom-up.
    image.pixels.foreach_set((rgba[::-1].astype(np.float32) / 255.0).ravel())
    image.pack()
    image.use_fake_user = True  # only the edge names it: without a user it would not be saved
    image[PLOT_KEY] = plot_key(edge)
    image[UNIT_KEY] = units
    _draw_preview(image, numbers)
    return image


def _draw_preview(image, numbers) -> None:
    """Draw the panel's picture of the plot into ``image``'s preview icon, at
    :data:`PREVIEW_SIZE`. Blender's own preview shrinks the plot to 128 pixels wide, and the
    sidebar then stretches it: its tick labels were specks."""
    width, height = PREVIEW_SIZE
    rgba = profile_plot.draw_profile(
        numbers["arc_lengths"], numbers["angles"], width=width, height=height
    )
    preview = image.preview_ensure()
    preview.image_size = (width, height)
    # Blender's rows run bottom-up, as the image's.
    preview.image_pixels_float.foreach_set((rgba[::-1].astype(np.float32) / 255.0).ravel())


def plot_image(edge):
    """The image holding ``edge``'s plot, or None: the image it names if that was drawn for it
    (or carries no tag: files of earlier versions), else the image drawn for it under another
    name (one that arrived renamed)."""
    key = plot_key(edge)
    image = bpy.data.images.get(edge.plot) if edge.plot else None
    if image is not None and image.get(PLOT_KEY, key) == key:
        return image
    return next((image for image in bpy.data.images if image.get(PLOT_KEY) == key), None)


def remove_plots(leaving) -> None:
    """Remove the plot images of the edge records ``leaving`` that no other edge shows (another
    object's duplicate of the same edge keeps its image)."""
    going = {edge.as_pointer() for edge in leaving}
    images = {image.name: image for edge in leaving if (image := plot_image(edge)) is not None}
    if not images:
        return
    for obj in bpy.data.objects:  # any type: a mesh converted to a curve keeps its records
        for edge in obj.vg.edges:
            if edge.as_pointer() not in going and (image := plot_image(edge)) is not None:
                images.pop(image.name, None)
    for image in images.values():
        bpy.data.images.remove(image)


def remove_orphaned_plots() -> int:
    """Remove the plot images no edge of any object shows any more and nothing else uses (their
    object was deleted: the fake user that keeps a plot in the file kept them for good, out of
    reach of Purge). Returns how many went.

    Images of linked libraries and images of earlier versions (untagged) are left alone.
    """
    tagged = {
        image.name: image
        for image in bpy.data.images
        if PLOT_KEY in image and image.library is None and image.users <= image.use_fake_user
    }
    if not tagged:
        return 0
    for obj in bpy.data.objects:  # any type: a mesh converted to a curve keeps its records
        for edge in obj.vg.edges:
            if (image := plot_image(edge)) is not None:
                tagged.pop(image.name, None)
    for image in tagged.values():
        bpy.data.images.remove(image)
    return len(tagged)

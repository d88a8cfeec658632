#!/usr/bin/env python3
"""Writes what the X server shows of a window as a binary PPM, for tests/viewer_input.sh:
   x_window_shot.py WINDOW_ID OUT.ppm
The window's pixels as a user sees them (XGetImage through libX11, no other package), the
part of it on the screen. It
grabs until two grabs in a row are equal, so a frame being swapped in is not caught half
drawn; it fails after 50 grabs that keep changing."""
import ctypes
import ctypes.util
import sys


class XImage(ctypes.Structure):
    # The leading members of Xlib's XImage, up to the colour masks.
    _fields_ = [("width", ctypes.c_int), ("height", ctypes.c_int), ("xoffset", ctypes.c_int),
                ("format", ctypes.c_int), ("data", ctypes.POINTER(ctypes.c_ubyte)), ("byte_order", ctypes.c_int),
                ("bitmap_unit", ctypes.c_int), ("bitmap_bit_order", ctypes.c_int), ("bitmap_pad", ctypes.c_int),
                ("depth", ctypes.c_int), ("bytes_per_line", ctypes.c_int), ("bits_per_pixel", ctypes.c_int),
                ("red_mask", ctypes.c_ulong), ("green_mask", ctypes.c_ulong), ("blue_mask", ctypes.c_ulong)]


class XWindowAttributes(ctypes.Structure):
    # The leading members of XWindowAttributes: position, size.
    _fields_ = [("x", ctypes.c_int), ("y", ctypes.c_int), ("width", ctypes.c_int), ("height", ctypes.c_int),
                ("border_width", ctypes.c_int), ("depth", ctypes.c_int), ("rest", ctypes.c_byte * 256)]


def shift_of(mask):
    shift = 0
    while mask and not mask & 1:
        mask >>= 1
        shift += 1
    return shift


def grab(x11, display, window):
    attributes = XWindowAttributes()
    if not x11.XGetWindowAttributes(display, window, ctypes.byref(attributes)):
        sys.exit("x_window_shot: no window %d" % window)
    # Only the part on the screen can be read: clip to it.
    root = x11.XDefaultRootWindow(display)
    screen = XWindowAttributes()
    x11.XGetWindowAttributes(display, root, ctypes.byref(screen))
    rx, ry, child = ctypes.c_int(), ctypes.c_int(), ctypes.c_ulong()
    x11.XTranslateCoordinates(display, window, root, 0, 0, ctypes.byref(rx), ctypes.byref(ry), ctypes.byref(child))
    w = min(attributes.width, screen.width - rx.value)
    h = min(attributes.height, screen.height - ry.value)
    if rx.value < 0 or ry.value < 0 or w <= 0 or h <= 0:
        sys.exit("x_window_shot: the window's corner is off the screen")
    all_planes = ctypes.c_ulong(-1).value
    image = x11.XGetImage(display, window, 0, 0, w, h, all_planes, 2)  # ZPixmap
    if not image:
        sys.exit("x_window_shot: XGetImage failed")
    im = image.contents
    if im.bits_per_pixel != 32:
        sys.exit("x_window_shot: expected 32 bits a pixel, the server gives %d" % im.bits_per_pixel)
    raw = ctypes.string_at(im.data, im.bytes_per_line * h)
    out = bytearray(w * h * 3)
    for k, mask in enumerate((im.red_mask, im.green_mask, im.blue_mask)):
        shift = shift_of(mask)
        if mask >> shift != 0xff or shift % 8:
            sys.exit("x_window_shot: expected 8-bit channels, the server's masks are %x %x %x" %
                     (im.red_mask, im.green_mask, im.blue_mask))
        byte = shift // 8 if im.byte_order == 0 else 3 - shift // 8  # LSBFirst = 0
        for y in range(h):
            row = y * im.bytes_per_line
            out[3 * w * y + k:3 * w * (y + 1):3] = raw[row + byte:row + 4 * w:4]
    return w, h, bytes(out)


def open_x11():
    """libX11 with the prototypes grab() needs, and the display ($DISPLAY)."""
    x11 = ctypes.CDLL(ctypes.util.find_library("X11") or "libX11.so.6")
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XGetWindowAttributes.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.POINTER(XWindowAttributes)]
    x11.XDefaultRootWindow.restype = ctypes.c_ulong
    x11.XDefaultRootWindow.argtypes = [ctypes.c_void_p]
    x11.XTranslateCoordinates.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_int, ctypes.c_int,
                                          ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int),
                                          ctypes.POINTER(ctypes.c_ulong)]
    x11.XGetImage.restype = ctypes.POINTER(XImage)
    x11.XGetImage.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int, ctypes.c_int, ctypes.c_uint,
                              ctypes.c_uint, ctypes.c_ulong, ctypes.c_int]
    display = x11.XOpenDisplay(None)
    if not display:
        sys.exit("x_window_shot: cannot open the display")
    return x11, display


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: x_window_shot.py WINDOW_ID OUT.ppm")
    x11, display = open_x11()
    window = int(sys.argv[1])
    last = None
    for _ in range(50):
        shot = grab(x11, display, window)
        if shot == last:
            w, h, pixels = shot
            with open(sys.argv[2], "wb") as f:
                f.write(b"P6\n%d %d\n255\n" % (w, h) + pixels)
            return
        last = shot
    sys.exit("x_window_shot: the window kept changing")


if __name__ == "__main__":
    main()

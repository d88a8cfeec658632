#!/usr/bin/env python3
"""Drops files on a window as a file manager does, through the X drag-and-drop protocol
(XDND, version 5), for tests/viewer_input.sh:
   x_drop.py WINDOW_ID FILE...
A source window owns the XdndSelection; XdndEnter (offering text/uri-list), XdndPosition at
the window's centre, then, once the target's XdndStatus accepts, XdndDrop; the target's
request for the selection is answered with the files' file:// URIs, and the script ends
when the target sends XdndFinished. Through libX11 (ctypes), no other package. Fails after
30 s without an answer."""
import ctypes
import ctypes.util
import os
import sys
import time
import urllib.parse

# X event types and the event as 24 longs (Xlib's XEvent union on LP64): the members of
# each event used here, by their index in longs.
CLIENT_MESSAGE, SELECTION_REQUEST, SELECTION_NOTIFY = 33, 30, 31
Event = ctypes.c_long * 24


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: x_drop.py WINDOW_ID FILE...")
    target = int(sys.argv[1])
    uris = "".join("file://" + urllib.parse.quote(os.path.abspath(f)) + "\r\n" for f in sys.argv[2:]).encode()

    x11 = ctypes.CDLL(ctypes.util.find_library("X11") or "libX11.so.6")
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XInternAtom.restype = ctypes.c_ulong
    x11.XInternAtom.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]
    x11.XDefaultRootWindow.restype = ctypes.c_ulong
    x11.XDefaultRootWindow.argtypes = [ctypes.c_void_p]
    x11.XCreateSimpleWindow.restype = ctypes.c_ulong
    x11.XCreateSimpleWindow.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int, ctypes.c_int, ctypes.c_uint,
                                        ctypes.c_uint, ctypes.c_uint, ctypes.c_ulong, ctypes.c_ulong]
    x11.XSetSelectionOwner.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong]
    x11.XSendEvent.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int, ctypes.c_long, ctypes.c_void_p]
    x11.XPending.argtypes = [ctypes.c_void_p]
    x11.XNextEvent.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    x11.XFlush.argtypes = [ctypes.c_void_p]
    x11.XChangeProperty.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_int,
                                    ctypes.c_int, ctypes.c_char_p, ctypes.c_int]
    x11.XTranslateCoordinates.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_int, ctypes.c_int,
                                          ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int),
                                          ctypes.POINTER(ctypes.c_ulong)]
    display = x11.XOpenDisplay(None)
    if not display:
        sys.exit("x_drop: cannot open the display")
    atom = lambda name: x11.XInternAtom(display, name.encode(), 0)
    enter, position, status, drop, finished = (atom("Xdnd" + n) for n in ("Enter", "Position", "Status", "Drop", "Finished"))
    selection, copy, uri_list = atom("XdndSelection"), atom("XdndActionCopy"), atom("text/uri-list")
    root = x11.XDefaultRootWindow(display)
    source = x11.XCreateSimpleWindow(display, root, 0, 0, 1, 1, 0, 0, 0)
    x11.XSetSelectionOwner(display, selection, source, 0)

    def send(message, *data):
        e = Event()
        e[0], e[4], e[5], e[6] = CLIENT_MESSAGE, target, message, 32
        for i, v in enumerate(data):
            e[7 + i] = v
        x11.XSendEvent(display, target, 0, 0, ctypes.byref(e))
        x11.XFlush(display)

    # The drop point: the window's centre area (left part, over the image), in root coordinates.
    rx, ry, child = ctypes.c_int(), ctypes.c_int(), ctypes.c_ulong()
    x11.XTranslateCoordinates(display, target, root, 250, 330, ctypes.byref(rx), ctypes.byref(ry), ctypes.byref(child))
    send(enter, source, 5 << 24, uri_list, 0, 0)
    send(position, source, 0, (rx.value << 16) | ry.value, 0, copy)
    dropped = False
    end = time.monotonic() + 30
    while time.monotonic() < end:
        if not x11.XPending(display):
            time.sleep(0.01)
            continue
        e = Event()
        x11.XNextEvent(display, ctypes.byref(e))
        kind = e[0] & 0xffffffff
        if kind == CLIENT_MESSAGE and e[5] == status and not dropped:
            if not e[8] & 1:
                sys.exit("x_drop: the window refused the drop")
            send(drop, source, 0, 0)
            dropped = True
        elif kind == CLIENT_MESSAGE and e[5] == finished:
            return
        elif kind == SELECTION_REQUEST:
            # requestor [5], selection [6], target [7], property [8], time [9]: the URIs.
            requestor, sel, tgt, prop, when = e[5], e[6], e[7], e[8], e[9]
            if tgt == uri_list:
                x11.XChangeProperty(display, requestor, prop, uri_list, 8, 0, uris, len(uris))
            reply = Event()
            reply[0], reply[2], reply[4], reply[5], reply[6] = SELECTION_NOTIFY, 1, requestor, sel, tgt
            reply[7], reply[8] = prop if tgt == uri_list else 0, when
            x11.XSendEvent(display, requestor, 0, 0, ctypes.byref(reply))
            x11.XFlush(display)
    sys.exit("x_drop: no answer from the window within 30 s (dropped: %s)" % dropped)


if __name__ == "__main__":
    main()

"""Synthesized mouse and keyboard input on $DISPLAY through the X Test
extension (libXtst, loaded with ctypes: no package beyond the X client
libraries GLFW already needs). The viewer tests drive a real window with it.

Usage: xinput.py STEP...  where a STEP is one of
  move X Y        the pointer to root-window pixel X, Y
  down B / up B   mouse button B (1 left, 3 right) pressed / released
  scroll N        N wheel clicks: N > 0 away from the user (zoom in), N < 0 toward
  key NAME S      hold the key NAME (an X keysym name: P, F, space) S seconds
  sleep S         wait S seconds
"""
import ctypes
import sys
import time

x11 = ctypes.CDLL('libX11.so.6')
xtst = ctypes.CDLL('libXtst.so.6')
x11.XOpenDisplay.restype = ctypes.c_void_p
x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
x11.XFlush.argtypes = [ctypes.c_void_p]
x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
x11.XStringToKeysym.restype = ctypes.c_ulong
x11.XStringToKeysym.argtypes = [ctypes.c_char_p]
x11.XKeysymToKeycode.restype = ctypes.c_ubyte
x11.XKeysymToKeycode.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
xtst.XTestFakeMotionEvent.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.c_int,
                                      ctypes.c_ulong]
xtst.XTestFakeButtonEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]
xtst.XTestFakeKeyEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]

display = x11.XOpenDisplay(None)
if not display:
    sys.exit('xinput.py: cannot open the display')


def flush():
    x11.XSync(display, 0)


args = sys.argv[1:]
i = 0
while i < len(args):
    step = args[i]
    if step == 'move':
        xtst.XTestFakeMotionEvent(display, -1, int(args[i + 1]), int(args[i + 2]), 0)
        i += 3
    elif step in ('down', 'up'):
        xtst.XTestFakeButtonEvent(display, int(args[i + 1]), 1 if step == 'down' else 0, 0)
        i += 2
    elif step == 'scroll':
        n = int(args[i + 1])
        for _ in range(abs(n)):
            button = 4 if n > 0 else 5
            xtst.XTestFakeButtonEvent(display, button, 1, 0)
            xtst.XTestFakeButtonEvent(display, button, 0, 0)
            flush()
            time.sleep(0.05)
        i += 2
    elif step == 'key':
        code = x11.XKeysymToKeycode(display, x11.XStringToKeysym(args[i + 1].encode()))
        if not code:
            sys.exit(f'xinput.py: no key {args[i + 1]}')
        xtst.XTestFakeKeyEvent(display, code, 1, 0)
        flush()
        time.sleep(float(args[i + 2]))
        xtst.XTestFakeKeyEvent(display, code, 0, 0)
        i += 3
    elif step == 'sleep':
        flush()
        time.sleep(float(args[i + 1]))
        i += 2
    else:
        sys.exit(f'xinput.py: unknown step {step}')
    flush()

// xdnd_drop: drops files onto an X11 window as a file manager does, through the XDND protocol (version 5,
// freedesktop.org's Drag-and-Drop Protocol for the X Window System): XdndEnter offering text/uri-list,
// XdndPosition at a point of the window, XdndDrop once the target accepts, then the file:// URIs handed over
// through the XdndSelection. xdotool cannot drag a file, so the user-session tests drop with this.
// Usage: xdnd_drop WINDOW_ID X Y FILE...   (X, Y in the window's coordinates; exit 0 when the target took
// the drop and said it finished, 1 when it refused or did not answer within 10 s, 2 on bad usage)
#include <X11/Xatom.h>
#include <X11/Xlib.h>

#include <cctype>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

// A path as a file URI: every byte but unreserved ones and '/' percent-encoded (RFC 8089, RFC 3986).
std::string file_uri(const char* path) {
    std::string uri = "file://";
    for (const unsigned char* p = reinterpret_cast<const unsigned char*>(path); *p; ++p) {
        if (std::isalnum(*p) || std::strchr("/-._~", *p)) {
            uri += static_cast<char>(*p);
        } else {
            char hex[4];
            std::snprintf(hex, sizeof hex, "%%%02X", *p);
            uri += hex;
        }
    }
    return uri;
}

void send(Display* d, Window target, Atom type, long l0, long l1, long l2, long l3, long l4) {
    XEvent e{};
    e.xclient.type = ClientMessage;
    e.xclient.display = d;
    e.xclient.window = target;
    e.xclient.message_type = type;
    e.xclient.format = 32;
    e.xclient.data.l[0] = l0;
    e.xclient.data.l[1] = l1;
    e.xclient.data.l[2] = l2;
    e.xclient.data.l[3] = l3;
    e.xclient.data.l[4] = l4;
    XSendEvent(d, target, False, NoEventMask, &e);
    XFlush(d);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 5) {
        std::fprintf(stderr, "usage: xdnd_drop WINDOW_ID X Y FILE...\n");
        return 2;
    }
    Display* d = XOpenDisplay(nullptr);
    if (!d) {
        std::fprintf(stderr, "xdnd_drop: cannot open the display\n");
        return 2;
    }
    const Window target = std::strtoul(argv[1], nullptr, 0);
    const int x = std::atoi(argv[2]), y = std::atoi(argv[3]);
    std::string uris;
    for (int i = 4; i < argc; ++i) uris += file_uri(argv[i]) + "\r\n";

    const Atom aware = XInternAtom(d, "XdndAware", False), enter = XInternAtom(d, "XdndEnter", False),
               position = XInternAtom(d, "XdndPosition", False), status = XInternAtom(d, "XdndStatus", False),
               drop = XInternAtom(d, "XdndDrop", False), finished = XInternAtom(d, "XdndFinished", False),
               selection = XInternAtom(d, "XdndSelection", False), copy = XInternAtom(d, "XdndActionCopy", False),
               uri_list = XInternAtom(d, "text/uri-list", False);
    // The target must say it takes drops.
    Atom type = None;
    int format = 0;
    unsigned long count = 0, after = 0;
    unsigned char* data = nullptr;
    if (XGetWindowProperty(d, target, aware, 0, 1, False, XA_ATOM, &type, &format, &count, &after, &data) != Success ||
        count == 0) {
        std::fprintf(stderr, "xdnd_drop: window 0x%lx is not XdndAware\n", target);
        return 1;
    }
    XFree(data);

    // The source: an unmapped window that owns the selection and receives the target's answers.
    const Window source = XCreateSimpleWindow(d, DefaultRootWindow(d), 0, 0, 1, 1, 0, 0, 0);
    XSetSelectionOwner(d, selection, source, CurrentTime);
    int root_x = 0, root_y = 0;
    Window child = None;
    XTranslateCoordinates(d, target, DefaultRootWindow(d), x, y, &root_x, &root_y, &child);
    send(d, target, enter, static_cast<long>(source), 5L << 24, static_cast<long>(uri_list), None, None);
    send(d, target, position, static_cast<long>(source), 0, (long(root_x) << 16) | root_y, CurrentTime,
         static_cast<long>(copy));

    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    bool dropped = false;
    while (std::chrono::steady_clock::now() < deadline) {
        if (!XPending(d)) {
            struct timespec pause = {0, 10'000'000};
            nanosleep(&pause, nullptr);
            continue;
        }
        XEvent e;
        XNextEvent(d, &e);
        if (e.type == ClientMessage && e.xclient.message_type == status && !dropped) {
            if (!(e.xclient.data.l[1] & 1)) {
                std::fprintf(stderr, "xdnd_drop: the target refused the drop\n");
                return 1;
            }
            send(d, target, drop, static_cast<long>(source), 0, CurrentTime, 0, 0);
            dropped = true;
        } else if (e.type == SelectionRequest) {
            // The target asks for the data: the URIs, into the property it names.
            XSelectionRequestEvent& r = e.xselectionrequest;
            XEvent reply{};
            reply.xselection.type = SelectionNotify;
            reply.xselection.display = d;
            reply.xselection.requestor = r.requestor;
            reply.xselection.selection = r.selection;
            reply.xselection.target = r.target;
            reply.xselection.time = r.time;
            reply.xselection.property = None;
            if (r.target == uri_list) {
                XChangeProperty(d, r.requestor, r.property, uri_list, 8, PropModeReplace,
                                reinterpret_cast<const unsigned char*>(uris.data()), static_cast<int>(uris.size()));
                reply.xselection.property = r.property;
            }
            XSendEvent(d, r.requestor, False, NoEventMask, &reply);
            XFlush(d);
        } else if (e.type == ClientMessage && e.xclient.message_type == finished) {
            XCloseDisplay(d);
            return 0;
        }
    }
    std::fprintf(stderr, "xdnd_drop: no answer from window 0x%lx within 10 s\n", target);
    return 1;
}

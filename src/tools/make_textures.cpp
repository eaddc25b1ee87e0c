// clothsim-make-textures: writes the two procedural textures the renderer uses, as 256x256 RGB PNGs, and the
// program's icon.
//   fabric.png  a tileable red-orange 2/2 twill weave, with lighter thread stripes every 32 px so that the
//               motion of the cloth stays visible.
//   crate.png   light blue-grey metal panels with a darker 12 px border and a diagonal cross brace, for the
//               cube collider.
//   clothsim.png the desktop icon (256x256 RGBA, installed under share/icons): an orange cloth with its grid
//               of springs, hanging from two pins, on a rounded dark-blue tile.
// Usage: clothsim-make-textures OUTPUT_DIR [ICON_DIR]. Output is deterministic (fixed-seed integer hashing, no clock or RNG), so
// regenerating never shows up as a change in git. Exit codes: 0 ok, 2 bad usage or a failed write.
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace {

constexpr int kSize = 256;
constexpr int kChannels = 3;

using Rgb = std::array<double, 3>;

class Image {
public:
    Image() : pixels_(static_cast<std::size_t>(kSize) * kSize * kChannels, 0) {}

    void set(int x, int y, const Rgb& c) {
        const std::size_t base = (static_cast<std::size_t>(y) * kSize + static_cast<std::size_t>(x)) * kChannels;
        for (std::size_t k = 0; k < kChannels; ++k) {
            pixels_[base + k] = static_cast<unsigned char>(std::clamp(std::lround(c[k]), 0L, 255L));
        }
    }

    [[nodiscard]] const unsigned char* data() const { return pixels_.data(); }

private:
    std::vector<unsigned char> pixels_;
};

// Integer hash (lowbias32 by Chris Wellons): well mixed, and identical on every platform, unlike std::rand or the
// standard distributions whose output is implementation-defined.
std::uint32_t hash32(std::uint32_t v) {
    v ^= v >> 16;
    v *= 0x7feb352dU;
    v ^= v >> 15;
    v *= 0x846ca68bU;
    v ^= v >> 16;
    return v;
}

// A seed per use keeps the noise layers uncorrelated with each other.
double hash01(std::uint32_t seed, int a, int b = 0) {
    const std::uint32_t h = hash32(seed ^ hash32(static_cast<std::uint32_t>(a) ^ hash32(static_cast<std::uint32_t>(b) + 0x9e3779b9U)));
    return static_cast<double>(h) / 4294967295.0;
}

// Value noise on a lattice that wraps every `cells` cells, so a texture built from it tiles seamlessly.
double periodic_noise(std::uint32_t seed, double x, double y, int cells) {
    const int x0 = static_cast<int>(std::floor(x));
    const int y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0;
    const double fy = y - y0;
    const auto wrap = [cells](int i) { return ((i % cells) + cells) % cells; };
    const auto corner = [&](int dx, int dy) { return hash01(seed, wrap(x0 + dx), wrap(y0 + dy)); };
    // Smoothstep weights hide the lattice; linear ones leave visible creases.
    const double sx = fx * fx * (3.0 - 2.0 * fx);
    const double sy = fy * fy * (3.0 - 2.0 * fy);
    const double top = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * sx;
    const double bottom = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * sx;
    return top + (bottom - top) * sy;
}

Rgb scale(const Rgb& c, double f) { return {c[0] * f, c[1] * f, c[2] * f}; }

Rgb mix(const Rgb& a, const Rgb& b, double t) {
    return {a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
}

Image make_fabric() {
    // 4 px threads give 64 threads per tile; 256 being a multiple of both the thread pitch and the 4-thread twill
    // repeat is what makes the weave wrap without a seam.
    constexpr int kPitch = 4;
    constexpr int kThreads = kSize / kPitch;
    constexpr int kTwillRepeat = 4;
    static_assert(kThreads % kTwillRepeat == 0, "the twill must repeat a whole number of times per tile");
    // Stripes are two threads wide every 8 threads (32 px): a single thread is too thin to read once mipmapped.
    constexpr int kStripeEvery = 8;
    constexpr int kStripeWidth = 2;

    // Warp and weft are dyed slightly differently, as in real cloth, so the twill diagonals read.
    const Rgb warp_colour{214.0, 92.0, 66.0};
    const Rgb weft_colour{198.0, 80.0, 58.0};
    const Rgb stripe_colour{226.0, 142.0, 106.0};

    Image img;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const int col = x / kPitch;
            const int row = y / kPitch;
            const double u = ((x % kPitch) + 0.5) / kPitch;
            const double v = ((y % kPitch) + 0.5) / kPitch;

            const int phase = (col + row) % kTwillRepeat;
            const bool warp_on_top = phase < kTwillRepeat / 2;
            const int thread = warp_on_top ? col : row;
            const double across = warp_on_top ? u : v;
            const double along = warp_on_top ? v : u;
            // Where the visible float sits in its two-cell run: threads bend down into the cloth at the float ends.
            const double run_pos = ((warp_on_top ? phase : phase - kTwillRepeat / 2) + along) / 2.0;

            Rgb colour = warp_on_top ? warp_colour : weft_colour;
            if (thread % kStripeEvery < kStripeWidth) {
                colour = mix(colour, stripe_colour, 0.55);
            }
            // Per-thread dye variation; the thread index already wraps with the tile.
            colour = scale(colour, 0.94 + 0.12 * hash01(warp_on_top ? 11U : 23U, thread));

            // A round thread is lit in the middle and shadowed towards the gaps between neighbours.
            const double roundness = std::pow(std::sin(std::numbers::pi * across), 0.7);
            const double dip = std::sin(std::numbers::pi * run_pos);
            double shade = (0.62 + 0.38 * roundness) * (0.80 + 0.20 * dip);

            // Fibre streaks run along the thread, so key them on thread and position along it.
            const int along_px = warp_on_top ? y : x;
            shade *= 0.96 + 0.08 * hash01(warp_on_top ? 37U : 41U, thread * 7 + (x + y) % 3, along_px / 2);
            // Low-frequency mottling keeps large areas from looking flat; 8 cells across the tile wrap with it.
            shade *= 0.94 + 0.12 * periodic_noise(53U, x / 32.0, y / 32.0, kSize / 32);
            shade *= 0.97 + 0.06 * hash01(67U, x, y);

            img.set(x, y, scale(colour, shade * 1.16));
        }
    }
    return img;
}

Image make_crate() {
    constexpr int kBorder = 12;
    constexpr double kBraceHalfWidth = 7.0;
    const Rgb panel{150.0, 168.0, 202.0};
    const Rgb border{88.0, 103.0, 132.0};
    const Rgb brace{130.0, 147.0, 181.0};
    const Rgb rivet{176.0, 190.0, 214.0};

    Image img;
    const double far = kSize - 1.0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const int edge_dist = std::min(std::min(x, y), std::min(kSize - 1 - x, kSize - 1 - y));
            Rgb c = panel;
            if (edge_dist < kBorder) {
                c = border;
                // A bevel (light outer lip, dark inner step) makes the frame read as raised at any texture scale.
                if (edge_dist < 2) {
                    c = scale(c, 1.25);
                } else if (edge_dist >= kBorder - 2) {
                    c = scale(c, 0.80);
                }
                // Rivets sit mid-border near each corner and at the middle of each side.
                const double mid = kBorder / 2.0 - 0.5;
                for (const double cx : {mid, far / 2.0, far - mid}) {
                    for (const double cy : {mid, far / 2.0, far - mid}) {
                        const double d = std::hypot(x - cx, y - cy);
                        if (d < 3.2) {
                            c = scale(rivet, 1.0 - 0.12 * (d / 3.2));
                        }
                    }
                }
            } else {
                const double d1 = std::abs(x - y) / std::numbers::sqrt2;
                const double d2 = std::abs(x + y - far) / std::numbers::sqrt2;
                const double d = std::min(d1, d2);
                if (d < kBraceHalfWidth) {
                    c = brace;
                    // Dark edge lines outline the brace so it stays subtle in colour yet clearly shaped.
                    if (d > kBraceHalfWidth - 1.2) {
                        c = scale(c, 0.82);
                    }
                } else if (edge_dist < kBorder + 3) {
                    // The frame casts a short shadow onto the panel.
                    c = scale(c, 0.90 + 0.10 * (edge_dist - kBorder) / 3.0);
                }
            }
            // Brushed-metal streaks: mostly per row, so they read as horizontal grain.
            const double grain = 0.97 + 0.06 * hash01(101U, y) * (0.6 + 0.4 * hash01(103U, x / 16, y));
            const double speckle = 0.98 + 0.04 * hash01(107U, x, y);
            const double stains = 0.95 + 0.08 * periodic_noise(109U, x / 64.0, y / 64.0, kSize / 64);
            img.set(x, y, scale(c, grain * speckle * stains));
        }
    }
    return img;
}

bool write_png(const std::filesystem::path& path, const Image& img) {
    const std::string name = path.string();
    if (stbi_write_png(name.c_str(), kSize, kSize, kChannels, img.data(), kSize * kChannels) == 0) {
        std::cerr << "clothsim-make-textures: failed to write " << name << '\n';
        return false;
    }
    std::cout << "wrote " << name << " (" << kSize << "x" << kSize << " RGB)\n";
    return true;
}

// The icon, straight RGBA (transparent outside the tile).
std::vector<unsigned char> make_icon() {
    std::vector<unsigned char> px(static_cast<std::size_t>(kSize) * kSize * 4, 0);
    auto put = [&](int x, int y, const Rgb& c, double alpha) {
        if (x < 0 || y < 0 || x >= kSize || y >= kSize) return;
        const std::size_t i = (static_cast<std::size_t>(y) * kSize + static_cast<std::size_t>(x)) * 4;
        for (std::size_t k = 0; k < 3; ++k) px[i + k] = static_cast<unsigned char>(std::clamp(std::lround(c[k]), 0L, 255L));
        px[i + 3] = static_cast<unsigned char>(std::clamp(std::lround(alpha * 255.0), 0L, 255L));
    };
    // The tile: a rounded square with a vertical gradient; its edge antialiased over one pixel.
    constexpr double kMargin = 8.0, kRadius = 40.0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const double cx = std::clamp(x + 0.5, kMargin + kRadius, kSize - kMargin - kRadius);
            const double cy = std::clamp(y + 0.5, kMargin + kRadius, kSize - kMargin - kRadius);
            const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy) - kRadius;
            const double alpha = std::clamp(0.5 - d, 0.0, 1.0);
            if (alpha > 0.0) put(x, y, mix(Rgb{46, 64, 96}, Rgb{22, 30, 48}, y / double(kSize)), alpha);
        }
    }
    // The cloth, splatted from a fine (u, v) grid: hung from its top corners, the top edge sags between the
    // pins and the lower part falls in three soft folds; shading follows the folds' slope.
    const double pi = std::numbers::pi;
    auto point = [&](double u, double v, double& x, double& y) {
        x = 52.0 + 152.0 * u + 10.0 * v * std::sin(3.0 * pi * u);
        y = 52.0 + 22.0 * std::sin(pi * u) * (1.0 - 0.6 * v) + 150.0 * v;
    };
    constexpr int kFine = 900, kCells = 8;
    for (int j = 0; j <= kFine; ++j) {
        for (int i = 0; i <= kFine; ++i) {
            const double u = i / double(kFine), v = j / double(kFine);
            double x = 0.0, y = 0.0;
            point(u, v, x, y);
            const double slope = v * std::cos(3.0 * pi * u);  // the folds' tilt toward the light
            Rgb c = scale(Rgb{226, 110, 52}, 0.78 + 0.22 * slope);
            const double gu = std::abs(u * kCells - std::round(u * kCells)), gv = std::abs(v * kCells - std::round(v * kCells));
            if (std::min(gu, gv) < 0.045) c = scale(c, 0.62);  // the springs between particles
            put(static_cast<int>(x), static_cast<int>(y), c, 1.0);
        }
    }
    // Two pins at the top corners: light discs with a dark rim.
    for (const double u : {0.0, 1.0}) {
        double px0 = 0.0, py0 = 0.0;
        point(u, 0.0, px0, py0);
        for (int y = int(py0) - 12; y <= int(py0) + 12; ++y) {
            for (int x = int(px0) - 12; x <= int(px0) + 12; ++x) {
                const double d = std::hypot(x + 0.5 - px0, y + 0.5 - py0);
                if (d < 9.0) put(x, y, d < 6.5 ? Rgb{236, 238, 242} : Rgb{90, 96, 110}, 1.0);
            }
        }
    }
    return px;
}

}  // namespace

int main(int argc, char** argv) {
    constexpr const char* kUsage = "usage: clothsim-make-textures OUTPUT_DIR [ICON_DIR]\n"
                                   "  writes OUTPUT_DIR/fabric.png and OUTPUT_DIR/crate.png, and ICON_DIR/clothsim.png\n";
    // A flag is never taken for a folder to write into (a folder named "-x" is written as ./-x).
    if (argc == 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h")) {
        std::cout << kUsage;
        return 0;
    }
    for (int i = 1; i < argc; ++i) {
        if (argv[i][0] == '-') {
            std::cerr << "clothsim-make-textures: unknown option " << argv[i] << '\n' << kUsage;
            return 2;
        }
    }
    if (argc != 2 && argc != 3) {
        std::cerr << kUsage;
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    // Creating the directory lets a build step point at a fresh output folder without a separate mkdir.
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        std::cerr << "clothsim-make-textures: cannot create directory " << dir.string() << ": " << ec.message() << '\n';
        return 2;
    }
    if (!write_png(dir / "fabric.png", make_fabric()) || !write_png(dir / "crate.png", make_crate())) {
        return 2;
    }
    if (argc == 3) {
        const std::filesystem::path icon_dir = argv[2];
        std::filesystem::create_directories(icon_dir, ec);
        const std::string icon = (icon_dir / "clothsim.png").string();
        const std::vector<unsigned char> pixels = make_icon();
        if (ec || stbi_write_png(icon.c_str(), kSize, kSize, 4, pixels.data(), kSize * 4) == 0) {
            std::cerr << "clothsim-make-textures: failed to write " << icon << '\n';
            return 2;
        }
        std::cout << "wrote " << icon << " (" << kSize << "x" << kSize << " RGBA)\n";
    }
    return 0;
}

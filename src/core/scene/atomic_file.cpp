#include "clothsim/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>

namespace clothsim {
namespace {

std::string describe(const std::filesystem::path& path, const std::string& what) {
    return std::string("cannot write '").append(path.string()).append("': ").append(what);
}

}  // namespace

bool write_file_atomically(const std::filesystem::path& path, std::string_view text, std::string& error) {
    const std::filesystem::path parent = path.parent_path().empty() ? "." : path.parent_path();
    struct stat st {};
    if (::stat(parent.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
        error = describe(path, "the directory '" + parent.string() + "' does not exist");
        return false;
    }
    if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        // Renaming over a directory fails anyway; over a device or a FIFO it would replace it: refuse both.
        error = describe(path, S_ISDIR(st.st_mode) ? "it is a directory" : "it is not a regular file");
        return false;
    }
    std::string temp = path.string() + ".tmp-XXXXXX";
    const int fd = ::mkstemp(temp.data());
    if (fd < 0) {
        error = describe(path, std::strerror(errno));
        return false;
    }
    auto fail = [&](int code) {
        ::close(fd);
        ::unlink(temp.c_str());
        error = describe(path, std::strerror(code));
        return false;
    };
    // A file-size limit (ulimit -f) would raise SIGXFSZ and kill the process; ignored, write() reports EFBIG.
    struct sigaction ignore {}, previous {};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGXFSZ, &ignore, &previous);
    std::size_t done = 0;
    int write_error = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            write_error = errno;
            break;
        }
        done += static_cast<std::size_t>(n);
    }
    ::sigaction(SIGXFSZ, &previous, nullptr);
    if (write_error != 0) return fail(write_error);
    if (::fsync(fd) != 0) return fail(errno);
    // mkstemp makes the file 0600; a saved scene gets the usual permissions (umask applies).
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd, 0666 & ~mask);
    if (::close(fd) != 0) {
        const int code = errno;
        ::unlink(temp.c_str());
        error = describe(path, std::strerror(code));
        return false;
    }
    if (::rename(temp.c_str(), path.c_str()) != 0) {
        const int code = errno;
        ::unlink(temp.c_str());
        error = describe(path, std::strerror(code));
        return false;
    }
    return true;
}

}  // namespace clothsim

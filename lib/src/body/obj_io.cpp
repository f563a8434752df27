/// \file
/// \brief A strict Wavefront OBJ reader and writer for triangle meshes.
///
/// The reader accepts exactly the subset documented in triangle_mesh.hpp and stops at the first
/// thing it does not understand, with the file, the line, what it expected and what it found:
/// a mesh silently read wrong is worse than no mesh.

#include <algorithm>
#include <cctype>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "grbd/body/triangle_mesh.hpp"
#include "grbd/core/checks.hpp"

namespace grbd::body {

namespace {

/// At most this many characters of an offending token go into a message.
constexpr std::size_t kMaxQuoted = 40;

/// `text` made printable for an error message: control and non-ASCII bytes as \xNN, long tokens
/// cut short with "...".
std::string quoted(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kMaxQuoted; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte >= 0x20 && byte < 0x7f) {
      out.push_back(static_cast<char>(byte));
    } else {
      constexpr char hex[] = "0123456789abcdef";
      out += "\\x";
      out.push_back(hex[byte >> 4]);
      out.push_back(hex[byte & 0xf]);
    }
  }
  if (text.size() > kMaxQuoted) out += "...";
  return "'" + out + "'";
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

/// The decimal order of magnitude of a well-formed decimal number (what std::from_chars matched:
/// an optional '-', digits with an optional '.', an optional exponent): the exponent of its
/// leading non-zero digit, so that 10^order ≤ |x| < 10^(order + 1); saturated far beyond the
/// range of double. Only its sign is used, to tell an overflow from an underflow.
std::int64_t decimal_order(std::string_view number) {
  constexpr std::int64_t kSaturated = std::int64_t{1} << 40;
  std::size_t i = number.starts_with('-') ? 1 : 0;
  std::int64_t order = 0;
  bool leading = true;    // no non-zero digit seen yet
  bool fraction = false;  // after the '.'
  for (; i < number.size() && number[i] != 'e' && number[i] != 'E'; ++i) {
    if (number[i] == '.') {
      fraction = true;
    } else if (leading && number[i] == '0') {
      if (fraction) --order;  // 0.001: each zero after the point lowers the order
    } else if (leading) {
      leading = false;
      if (fraction) --order;  // the first non-zero digit after the point: 0.1 is 10^-1
    } else if (!fraction) {
      ++order;  // a further digit before the point: 12 is 10^1
    }
    order = std::clamp(order, -kSaturated, kSaturated);
  }
  if (i < number.size()) {  // the exponent
    ++i;
    const bool negative = i < number.size() && number[i] == '-';
    if (i < number.size() && (number[i] == '-' || number[i] == '+')) ++i;
    std::int64_t exponent = 0;
    for (; i < number.size(); ++i) {
      exponent = std::min(10 * exponent + (number[i] - '0'), kSaturated);
    }
    order += negative ? -exponent : exponent;
  }
  return order;
}

/// The whitespace-separated tokens of one line (spaces and tabs only: any other byte, a control
/// character included, belongs to a token and is then reported as found).
std::vector<std::string_view> tokenize(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

/// Parses the OBJ text of one file; `name` is the file name for messages.
class ObjParser {
 public:
  explicit ObjParser(std::string name) : name_(std::move(name)) {}

  TriangleMesh parse(std::string_view text) {
    // A UTF-8 byte order mark, which some editors write, is not part of the first statement.
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    line_ = 0;
    while (!text.empty()) {
      const std::size_t end = text.find('\n');
      std::string_view line = text.substr(0, end);
      text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
      ++line_;
      if (line.ends_with('\r')) line.remove_suffix(1);  // Windows line ends
      if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
        line = line.substr(0, hash);  // a comment runs to the end of the line
      }
      line_text_ = line.substr(0, line.find_last_not_of(" \t") + 1);  // npos + 1 = 0
      line_text_.remove_prefix(std::min(line_text_.find_first_not_of(" \t"), line_text_.size()));
      statement(tokenize(line));
    }
    if (faces_.empty()) {
      line_ = std::max<std::size_t>(line_, 1);
      fail("at least one face ('f i j k')",
           "end of file after " + std::to_string(vertices_.size()) + " vertices and no 'f' line",
           /*quote=*/false);
    }
    TriangleMesh mesh;
    mesh.V.resize(static_cast<Eigen::Index>(vertices_.size()), 3);
    for (std::size_t i = 0; i < vertices_.size(); ++i) {
      mesh.V.row(static_cast<Eigen::Index>(i)) = vertices_[i];
    }
    mesh.F.resize(static_cast<Eigen::Index>(faces_.size()), 3);
    for (std::size_t f = 0; f < faces_.size(); ++f) {
      for (int k = 0; k < 3; ++k) {
        mesh.F(static_cast<Eigen::Index>(f), k) = faces_[f][static_cast<std::size_t>(k)];
      }
    }
    return mesh;
  }

 private:
  [[noreturn]] void fail(std::string_view expected, std::string_view found,
                         bool quote = true) const {
    throw MeshError(name_ + ":" + std::to_string(line_) + ": expected " + std::string(expected) +
                    ", found " + (quote ? quoted(found) : std::string(found)));
  }

  void statement(const std::vector<std::string_view>& tokens) {
    if (tokens.empty()) return;
    const std::string_view keyword = tokens[0];
    if (keyword == "v") {
      vertex(tokens);
    } else if (keyword == "f") {
      face(tokens);
    } else if (keyword == "vt" || keyword == "vn" || keyword == "vp" || keyword == "o" ||
               keyword == "g" || keyword == "s" || keyword == "usemtl" || keyword == "mtllib") {
      // Texture coordinates, normals, names, groups, smoothing and materials carry nothing that
      // the mass properties need.
    } else {
      // A keyword is quoted only when it looks like one (a short word): a file that is not OBJ
      // at all (a password file named by mistake or by a scene from elsewhere) has nothing of
      // its text repeated in the message.
      const bool word = keyword.size() <= 16 && std::all_of(keyword.begin(), keyword.end(), [](char c) {
                          return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
                        });
      fail("a statement 'v', 'f', 'vt', 'vn', 'vp', 'o', 'g', 's', 'usemtl', 'mtllib' or a "
           "comment",
           word ? keyword : std::string_view("a line that is not OBJ (the file is not an OBJ file)"),
           word);
    }
  }

  double number(std::string_view token) const {
    std::string_view digits = token;
    // std::from_chars does not take a leading '+', which OBJ writers sometimes emit.
    if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-' && digits[1] != '+') {
      digits.remove_prefix(1);
    }
    double x = 0.0;
    const char* const last = digits.data() + digits.size();
    const auto [end, error] = std::from_chars(digits.data(), last, x);
    if (error == std::errc::result_out_of_range && end == last) {
      // A well-formed decimal number whose magnitude is beyond the range of double. Below the
      // smallest subnormal its correctly rounded value is ±0 (as strtod gives it), a harmless
      // coordinate; above the largest double there is no value to give.
      if (decimal_order(digits) < 0) return digits[0] == '-' ? -0.0 : 0.0;
      fail("a decimal number of magnitude at most " +
               format_number(std::numeric_limits<double>::max()) + " (the largest double)",
           quoted(token) + ", which overflows", /*quote=*/false);
    }
    if (error != std::errc() || end != last || !std::isfinite(x)) {
      fail("a finite decimal number", token);
    }
    return x;
  }

  void vertex(const std::vector<std::string_view>& tokens) {
    if (tokens.size() < 4) fail("three coordinates 'v x y z [w]'", line_text_);
    if (tokens.size() > 5) {
      fail("'v x y z [w]' to end the line", tokens[5]);
    }
    Eigen::RowVector3d x;
    for (int k = 0; k < 3; ++k) x[k] = number(tokens[static_cast<std::size_t>(k) + 1]);
    if (tokens.size() == 5) number(tokens[4]);  // the weight w is checked, but not used
    vertices_.push_back(x);
  }

  /// An optional texture or normal index of a vertex reference: checked, not used, so any
  /// non-zero integer will do, even one beyond the range of int.
  void attribute_index(std::string_view part, std::string_view token) const {
    std::int64_t value = 0;
    const char* const last = part.data() + part.size();
    const auto [end, error] = std::from_chars(part.data(), last, value);
    const bool integer =
        end == last && (error == std::errc() || error == std::errc::result_out_of_range);
    if (!integer || (error == std::errc() && value == 0)) {
      fail("a vertex reference 'i', 'i/t', 'i//n' or 'i/t/n' with non-zero integers", token);
    }
  }

  /// The zero-based vertex index of one vertex reference of an 'f' line.
  int vertex_index(std::string_view token) const {
    constexpr std::string_view form = "a vertex reference 'i', 'i/t', 'i//n' or 'i/t/n'";
    const std::size_t slash = token.find('/');
    const std::string_view index = token.substr(0, slash);
    if (slash != std::string_view::npos) {
      const std::string_view rest = token.substr(slash + 1);
      const std::size_t second = rest.find('/');
      if (second == std::string_view::npos) {
        attribute_index(rest, token);  // i/t
      } else {
        const std::string_view t = rest.substr(0, second);
        const std::string_view n = rest.substr(second + 1);
        if (!t.empty()) attribute_index(t, token);  // i/t/n, or i//n with t empty
        attribute_index(n, token);
      }
    }
    std::int64_t i = 0;
    const char* const last = index.data() + index.size();
    const auto [end, error] = std::from_chars(index.data(), last, i);
    if (end != last || (error != std::errc() && error != std::errc::result_out_of_range)) {
      fail(form, token);
    }
    // Positive indices count from 1 at the first vertex of the file, negative ones back from the
    // last vertex read so far (−1 is the latest). An integer beyond the range of int64 (and so of
    // any vertex count) is out of range like any other too large index.
    const auto count = static_cast<std::int64_t>(vertices_.size());
    const bool representable = error == std::errc();
    const std::int64_t zero_based = !representable ? -1 : (i > 0 ? i - 1 : count + i);
    if (i == 0 || zero_based < 0 || zero_based >= count) {
      const std::string range =
          count == 0 ? std::string("none (no vertex read yet)")
                     : "[1, " + std::to_string(count) + "] or [-" + std::to_string(count) + ", -1]";
      fail("a vertex index in " + range, token);
    }
    return static_cast<int>(zero_based);
  }

  void face(const std::vector<std::string_view>& tokens) {
    if (tokens.size() < 4) fail("a face of at least three vertices 'f i j k ...'", line_text_);
    std::vector<int> polygon;
    polygon.reserve(tokens.size() - 1);
    for (std::size_t k = 1; k < tokens.size(); ++k) polygon.push_back(vertex_index(tokens[k]));
    // A polygon v0 v1 … v(n−1) becomes the fan (v0, v(k), v(k+1)), which keeps its orientation.
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
      faces_.push_back({polygon[0], polygon[k], polygon[k + 1]});
    }
  }

  std::string name_;
  std::size_t line_ = 0;
  std::string_view line_text_;  ///< the current line, comment removed, for messages
  std::vector<Eigen::RowVector3d> vertices_;
  std::vector<std::array<int, 3>> faces_;
};

/// The kind of a file that is not a regular file, for a message.
std::string file_kind(std::filesystem::file_type type) {
  using std::filesystem::file_type;
  switch (type) {
    case file_type::fifo:
      return "a FIFO (named pipe)";
    case file_type::character:
      return "a character device";
    case file_type::block:
      return "a block device";
    case file_type::socket:
      return "a socket";
    default:
      return "a file of an unknown type";
  }
}

/// Closes a file of C stdio.
struct CloseFile {
  void operator()(std::FILE* file) const { std::fclose(file); }
};

/// The text of errno's error, or a stand-in where the library left errno unset.
std::string errno_reason(int error) {
  return error != 0 ? std::generic_category().message(error) : std::string("unknown reason");
}

}  // namespace

TriangleMesh read_obj(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string cannot = name + ": cannot read the OBJ file: ";
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) {
    // ENOENT, or ENOTDIR for a path through a file: either way no file has this name.
    const bool plain = !ec || ec == std::errc::no_such_file_or_directory;
    throw MeshError(cannot + "no such file" + (plain ? "" : " (" + ec.message() + ")"));
  }
  if (ec) {
    // The path may name a file, but it cannot be examined: a loop of symbolic links, a name
    // too long, a directory on the way that may not be searched.
    throw MeshError(cannot + "cannot examine the path: " + ec.message());
  }
  if (std::filesystem::is_directory(status)) {
    throw MeshError(cannot + "it is a directory");
  }
  if (!std::filesystem::is_regular_file(status)) {
    // A device or a pipe (/dev/zero, a FIFO) may never end, and opening a FIFO blocks until a
    // writer comes: it is refused from its type, without being opened.
    throw MeshError(cannot + "not a regular file but " + file_kind(status.type()) +
                    ", whose reading might never end");
  }
  // C stdio rather than a stream: it reports the reason of a failure in errno, where a file
  // stream throws std::ios_base::failure on a read error (EIO) or says nothing.
  errno = 0;
  const std::unique_ptr<std::FILE, CloseFile> file(std::fopen(name.c_str(), "rb"));
  if (!file) {
    throw MeshError(name + ": cannot open the OBJ file for reading: " + errno_reason(errno));
  }
  std::string text;
  std::array<char, 1 << 16> buffer;
  for (;;) {
    errno = 0;
    const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), file.get());
    text.append(buffer.data(), n);
    if (n < buffer.size()) break;
  }
  if (std::ferror(file.get())) {
    throw MeshError(cannot + "read error after " + std::to_string(text.size()) +
                    " bytes: " + errno_reason(errno));
  }
  return ObjParser(name).parse(text);
}

void write_obj(const TriangleMesh& mesh, const std::filesystem::path& path,
               std::string_view comment) {
  const std::string name = path.string();
  // Refuse what read_obj() would refuse, so that every file written here reads back.
  if (mesh.F.rows() == 0) {
    throw MeshError(name + ": cannot write an OBJ file without faces");
  }
  if (!mesh.V.allFinite()) {
    throw MeshError(name + ": cannot write non-finite vertex coordinates to an OBJ file");
  }
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.V.rows()) {
    throw MeshError(name + ": cannot write an OBJ file with face indices outside [0, " +
                    std::to_string(mesh.V.rows()) + ")");
  }
  std::string text;
  if (!comment.empty()) {
    for (std::size_t start = 0;;) {
      const std::size_t end = comment.find('\n', start);
      text.append("# ").append(comment.substr(start, end - start)).append("\n");
      if (end == std::string_view::npos) break;
      start = end + 1;
    }
  }
  // format_number() is independent of the C locale, and its 17 significant digits identify
  // every double: read_obj() gives back exactly these numbers.
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    text += 'v';
    for (int k = 0; k < 3; ++k) text += ' ' + format_number(mesh.V(i, k));
    text += '\n';
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    text += 'f';
    for (int k = 0; k < 3; ++k) text += ' ' + std::to_string(mesh.F(f, k) + 1);
    text += '\n';
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw MeshError(name + ": cannot open the OBJ file for writing");
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) {
    throw MeshError(name + ": cannot write the OBJ file: write error");
  }
}

}  // namespace grbd::body

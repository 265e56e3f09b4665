#include "dynamics/urdf_text.hpp"

#include <tinyxml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "dynamics/builder.hpp"  // ModelError

namespace saltus::dynamics {

namespace {

[[noreturn]] void fail(const std::string& where, const std::string& what) { throw ModelError(where + ": " + what); }

// A value for a message: at most 60 characters (a million-digit number is shortened).
std::string shortened(const std::string& value) {
  return value.size() <= 60 ? value : value.substr(0, 57) + "...";
}

// Text that is not XML at all: urdfdom would say only "Error document empty".
void checkXmlText(const std::string& xml, const std::string& source_name) {
  if (xml.find_first_not_of(" \t\r\n") == std::string::npos)
    fail(source_name, "the file is empty; expected a URDF (<robot name=...> with links and joints)");
  const std::size_t nul = xml.find('\0');
  if (nul != std::string::npos)
    fail(source_name + ":" + std::to_string(1 + std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(nul), '\n')),
         "a NUL byte at offset " + std::to_string(nul) + ": binary content, expected a URDF (XML text)");
  // well-formed UTF-8: TinyXML steps over the end of the text after a cut multi-byte character
  int line = 1;
  for (std::size_t i = 0; i < xml.size();) {
    const unsigned char c = static_cast<unsigned char>(xml[i]);
    if (c == '\n') ++line;
    const int extra = c < 0x80 ? 0 : (c >> 5) == 0x6 ? 1 : (c >> 4) == 0xE ? 2 : (c >> 3) == 0x1E ? 3 : -1;
    bool ok = extra >= 0 && i + static_cast<std::size_t>(extra) < xml.size();
    for (int k = 1; ok && k <= extra; ++k) ok = (static_cast<unsigned char>(xml[i + static_cast<std::size_t>(k)]) >> 6) == 0x2;
    if (!ok)
      fail(source_name + ":" + std::to_string(line),
           "a byte that is not UTF-8 text at offset " + std::to_string(i) + "; expected a URDF (XML in UTF-8)");
    i += static_cast<std::size_t>(extra) + 1;
  }
  const std::size_t bom = xml.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;  // a byte-order mark, exactly
  const std::size_t first = xml.find_first_not_of(" \t\r\n", bom);
  if (first == std::string::npos)
    fail(source_name, "the file is empty; expected a URDF (<robot name=...> with links and joints)");
  if (xml[first] != '<')
    fail(source_name + ":" + std::to_string(1 + std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(first), '\n')),
         "expected a URDF (XML starting with '<'), got text starting with '" + xml.substr(first, 12) + "'");
}


// Refuses XML whose elements nest deeper than kMaxXmlDepth, naming the line: TinyXML, under
// urdfdom, parses recursively and overflows the stack near 10^5 levels. A scan of the tags
// (comments, CDATA, processing instructions skipped; quoted attribute values may hold '>');
// malformed XML is left to the parser's own message.
void checkXmlNesting(const std::string& xml, const std::string& source_name) {
  int depth = 0, line = 1;
  const std::size_t n = xml.size();
  auto skipTo = [&](std::size_t from, const char* end) {
    const std::size_t k = xml.find(end, from);
    const std::size_t stop = k == std::string::npos ? n : k + std::strlen(end);
    line += static_cast<int>(std::count(xml.begin() + static_cast<std::ptrdiff_t>(from),
                                        xml.begin() + static_cast<std::ptrdiff_t>(stop), '\n'));
    return stop;
  };
  for (std::size_t i = 0; i < n;) {
    if (xml[i] == '\n') ++line;
    if (xml[i] != '<') {
      ++i;
      continue;
    }
    if (xml.compare(i, 4, "<!--") == 0) {
      i = skipTo(i + 4, "-->");
    } else if (xml.compare(i, 9, "<![CDATA[") == 0) {
      i = skipTo(i + 9, "]]>");
    } else if (xml.compare(i, 2, "<?") == 0) {
      i = skipTo(i + 2, "?>");
    } else if (xml.compare(i, 2, "<!") == 0) {
      // A DTD: urdfdom's parser does not expand entities, so "&name;" in a value would be read
      // as written or the document dropped ("no robot element"); a URDF declares none.
      const std::size_t close = xml.find('>', i);
      const std::string declaration = xml.substr(i, close == std::string::npos ? 40 : std::min<std::size_t>(close - i, 40));
      if (declaration.find('[') != std::string::npos || xml.compare(i, 9, "<!ENTITY ") == 0)
        fail(source_name + ":" + std::to_string(line),
             "a DTD with declarations ('" + declaration.substr(0, declaration.find('[') + 1) +
                 "…'); a URDF declares no entities (XML entities are not expanded)");
      i = skipTo(i + 2, ">");
    } else if (xml.compare(i, 2, "</") == 0) {
      depth = std::max(0, depth - 1);
      i = skipTo(i + 2, ">");
    } else {  // an opening tag: up to its '>' outside quotes; "/>" closes it at once
      const int tag_line = line;
      char quote = 0;
      std::size_t j = i + 1;
      for (; j < n && (quote || xml[j] != '>'); ++j) {
        if (xml[j] == '\n') ++line;
        if (quote ? xml[j] == quote : (xml[j] == '"' || xml[j] == '\'')) quote = quote ? 0 : xml[j];
      }
      if (j >= n) return;  // unterminated: the parser says so
      if (xml[j - 1] != '/' && ++depth > kMaxXmlDepth)
        fail(source_name + ":" + std::to_string(tag_line),
             "XML elements nested deeper than " + std::to_string(kMaxXmlDepth) +
                 " levels; a URDF nests a few (robot, link, visual, geometry, mesh)");
      i = j + 1;
    }
  }
}


// Every attribute token written as a number must survive its conversion to a double: urdfdom
// would read "1e-400" as 0 and "1e400" as inf and a check would then report a value never
// written. (A subnormal such as 1e-320 converts to itself and passes.)
void checkNumbers(const TiXmlNode* parent, const std::string& source_name) {
  for (const TiXmlElement* e = parent->FirstChildElement(); e; e = e->NextSiblingElement()) {
    for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      std::istringstream tokens(a->ValueStr());
      for (std::string token; tokens >> token;) {
        errno = 0;
        char* end = nullptr;
        const double x = std::strtod(token.c_str(), &end);
        const bool number = end == token.c_str() + token.size() && token.find_first_of("xXpP") == std::string::npos &&
                            (std::isdigit(static_cast<unsigned char>(token[0])) || token[0] == '.' ||
                             ((token[0] == '-' || token[0] == '+') && token.size() > 1));
        if (number && errno == ERANGE && (x == 0 || std::isinf(x)))
          fail(source_name + ":" + std::to_string(e->Row()),
               "<" + e->ValueStr() + " " + a->Name() + "=\"" + shortened(a->ValueStr()) + "\">: '" + shortened(token) +
                   "' is out of the range of a double (it would be read as " + (x == 0 ? "0" : "infinite") +
                   "); expected a number a double holds (magnitude below 1.8e308 and, unless 0, above 4.9e-324)");
      }
    }
    checkNumbers(e, source_name);  // recursion bounded by kMaxXmlDepth
  }
}

}  // namespace

UrdfText::UrdfText(const std::string& xml, std::string source)
    : xml_(xml), source_(std::move(source)), document_(std::make_unique<TiXmlDocument>()) {
  checkXmlText(xml, source_);
  checkXmlNesting(xml, source_);
  // The XML syntax, with the row TinyXML (urdfdom's parser) stopped at, which urdfdom drops.
  document_->Parse(xml.c_str(), nullptr, TIXML_ENCODING_UTF8);
  if (document_->Error())
    fail(source_ + ":" + std::to_string(std::max(1, document_->ErrorRow())),
         std::string("not well-formed XML (") + document_->ErrorDesc() + "); expected a URDF");
  checkNumbers(document_.get(), source_);
}

UrdfText::~UrdfText() = default;

const TiXmlElement* UrdfText::find(const std::string& tag, const std::string& owner, const std::string& path) const {
  const TiXmlElement* robot = document_->RootElement();
  if (!robot) return nullptr;
  const TiXmlElement* e = robot->FirstChildElement(tag);
  while (e && !(e->Attribute("name") && owner == e->Attribute("name"))) e = e->NextSiblingElement(tag);
  std::size_t start = 0;
  while (e && start < path.size()) {
    const std::size_t slash = path.find('/', start);
    const std::string child = path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
    e = e->FirstChildElement(child);
    start = slash == std::string::npos ? path.size() : slash + 1;
  }
  return e;
}

std::string UrdfText::where(const std::string& tag, const std::string& owner, const std::string& path) const {
  const TiXmlElement* e = find(tag, owner, path);
  if (!e && !path.empty()) e = find(tag, owner, "");
  return e ? source_ + ":" + std::to_string(e->Row()) : source_;
}

std::string UrdfText::written(const std::string& tag, const std::string& owner, const std::string& path) const {
  const TiXmlElement* e = find(tag, owner, path);
  if (!e) return "";
  std::string s = "<" + e->ValueStr();
  for (const TiXmlAttribute* a = e->FirstAttribute(); a; a = a->Next())
    s += " " + std::string(a->Name()) + "=\"" + shortened(a->ValueStr()) + "\"";
  return s + "/>";
}

std::string UrdfText::urdfdomLocation(const std::string& summary, std::string* quoted) const {
  const std::string& xml = xml_;
  const std::string& source_name = source_;
  std::size_t at = std::string::npos;
  for (std::size_t open = summary.find('['); open != std::string::npos; open = summary.find('[', open + 1)) {
    const std::size_t close = summary.find(']', open);
    if (close == std::string::npos) break;
    const std::string token = summary.substr(open + 1, close - open - 1);
    if (token.empty()) continue;
    for (const std::string& pattern : {"name=\"" + token + "\"", "\"" + token + "\""}) {
      const std::size_t k = xml.find(pattern);
      if (k != std::string::npos) {
        at = k;
        break;
      }
    }
    if (at != std::string::npos) break;
  }
  const std::size_t element = summary.find("element ");
  if (element != std::string::npos) {
    const std::size_t end = summary.find(' ', element + 8);
    const std::string attribute = summary.substr(element + 8, end == std::string::npos ? std::string::npos : end - element - 8);
    const std::size_t k = xml.find(attribute + "=", at == std::string::npos ? 0 : at);
    if (!attribute.empty() && k != std::string::npos) {
      at = k;
      const std::size_t q = k + attribute.size() + 1;
      if (q < xml.size() && (xml[q] == '"' || xml[q] == '\'')) {
        const std::size_t e = xml.find(xml[q], q + 1);
        if (e != std::string::npos) *quoted = "; " + attribute + " is '" + xml.substr(q + 1, e - q - 1) + "'";
      }
    }
  }
  if (at == std::string::npos) return source_name;
  return source_name + ":" + std::to_string(1 + std::count(xml.begin(), xml.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

}  // namespace saltus::dynamics

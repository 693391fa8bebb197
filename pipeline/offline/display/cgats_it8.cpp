// CGATS tables through Little CMS 2's IT8 functions.
#include <algorithm>
#include <cstdlib>
#include <memory>

#include <fmt/format.h>
#include <lcms2.h>

#include <pipeline/base/assert.h>
#include <pipeline/offline/display/cgats_it8.h>

namespace replica::pipeline::display {
namespace {

struct ContextFree {
    void operator()(void* c) const { cmsDeleteContext(static_cast<cmsContext>(c)); }
};
struct It8Free {
    void operator()(void* h) const { cmsIT8Free(static_cast<cmsHANDLE>(h)); }
};
using ContextPtr = std::unique_ptr<void, ContextFree>;
using It8Ptr = std::unique_ptr<void, It8Free>;

// lcms2's first error of one load, through its context's user data.
void keepFirstError(cmsContext ctx, cmsUInt32Number /*code*/, const char* text)
{
    auto* first = static_cast<std::string*>(cmsGetContextUserData(ctx));
    if (first != nullptr && first->empty() && text != nullptr) {
        *first = text;
    }
}

// lcms2 says "FILE: Line N, what" (FILE empty for a file read from memory): "source:N: what".
std::string withSource(const std::string& message, const std::string& source)
{
    const auto at = message.find("Line ");
    if (at != std::string::npos) {
        char* end = nullptr;
        const long line = std::strtol(message.c_str() + at + 5, &end, 10);
        if (end != message.c_str() + at + 5) {
            std::string what(end);
            what.erase(0, std::min(what.find_first_not_of(", "), what.size()));
            while (!what.empty() && (what.back() == '\n' || what.back() == ' ')) {
                what.pop_back();
            }
            return fmt::format("{}:{}: {}", source, line, what);
        }
    }
    return fmt::format("{}: {}", source,
                       message.empty() ? "lcms2 cannot read it as CGATS" : message);
}

std::string trimmed(const char* s)
{
    std::string out = s == nullptr ? "" : s;
    while (!out.empty() && (out.back() == ' ' || out.back() == '\t')) {
        out.pop_back();
    }
    return out;
}

} // namespace

Expected<CgatsTable> readIt8Table(const std::string& text,
                                  const std::string& source,
                                  std::size_t fields,
                                  const std::vector<int>& rowLines)
{
    std::string firstError;
    ContextPtr ctx(cmsCreateContext(nullptr, &firstError));
    if (!ctx) {
        return makeError(ErrorCode::Io, fmt::format("{}: lcms2 cannot start", source));
    }
    cmsSetLogErrorHandlerTHR(static_cast<cmsContext>(ctx.get()), keepFirstError);
    It8Ptr h(cmsIT8LoadFromMem(static_cast<cmsContext>(ctx.get()), text.data(),
                               static_cast<cmsUInt32Number>(text.size())));
    // lcms2 logs some errors and still returns a table (cut short where the error was).
    if (!h || !firstError.empty() || cmsIT8SetTable(h.get(), 0) < 0) {
        return makeError(ErrorCode::Corrupt, withSource(firstError, source));
    }
    CgatsTable t;
    t.identifier = trimmed(cmsIT8GetSheetType(h.get()));
    char** names = nullptr;
    const int nProps = cmsIT8EnumProperties(h.get(), &names);
    for (int i = 0; i < nProps; ++i) {
        const std::string name = names[i];
        if (name != "NUMBER_OF_FIELDS" && name != "NUMBER_OF_SETS") {
            t.keywords.emplace_back(name, trimmed(cmsIT8GetProperty(h.get(), names[i])));
        }
    }
    char** format = nullptr;
    const int nFields = cmsIT8EnumDataFormat(h.get(), &format);
    for (int i = 0; i < nFields; ++i) {
        t.fields.emplace_back(format[i] == nullptr ? "" : format[i]);
    }
    if (t.fields.size() != fields) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: lcms2 reads {} fields where the format lists {}", source,
                                     t.fields.size(), fields));
    }
    for (std::size_t r = 0; r < rowLines.size(); ++r) {
        std::vector<std::string> row;
        for (std::size_t c = 0; c < fields; ++c) {
            const char* v = cmsIT8GetDataRowCol(h.get(), static_cast<int>(r), static_cast<int>(c));
            if (v == nullptr) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}:{}: lcms2 has no {} in this row", source,
                                             rowLines[r], t.fields[c]));
            }
            row.emplace_back(v);
        }
        t.rows.push_back(std::move(row));
    }
    t.rowLines = rowLines;
    return t;
}

std::string writeIt8Table(const CgatsTable& t)
{
    It8Ptr h(cmsIT8Alloc(nullptr));
    REPLICA_ASSERT(h != nullptr, "lcms2 cannot allocate a CGATS table");
    bool ok = cmsIT8SetSheetType(h.get(), t.identifier.c_str()) != 0;
    for (const auto& [k, v] : t.keywords) {
        ok = ok && cmsIT8SetPropertyStr(h.get(), k.c_str(), v.c_str()) != 0;
    }
    ok = ok && cmsIT8SetPropertyDbl(h.get(), "NUMBER_OF_FIELDS",
                                    static_cast<double>(t.fields.size())) != 0;
    for (std::size_t c = 0; c < t.fields.size(); ++c) {
        ok = ok && cmsIT8SetDataFormat(h.get(), static_cast<int>(c), t.fields[c].c_str()) != 0;
    }
    ok = ok &&
         cmsIT8SetPropertyDbl(h.get(), "NUMBER_OF_SETS", static_cast<double>(t.rows.size())) != 0;
    for (std::size_t r = 0; r < t.rows.size(); ++r) {
        for (std::size_t c = 0; c < t.rows[r].size(); ++c) {
            ok = ok && cmsIT8SetDataRowCol(h.get(), static_cast<int>(r), static_cast<int>(c),
                                           t.rows[r][c].c_str()) != 0;
        }
    }
    cmsUInt32Number size = 0;
    ok = ok && cmsIT8SaveToMem(h.get(), nullptr, &size) != 0 && size > 0;
    std::string out(ok ? size : 0, '\0');
    ok = ok && cmsIT8SaveToMem(h.get(), out.data(), &size) != 0;
    REPLICA_ASSERT(ok, "lcms2 cannot write the CGATS table");
    out.resize(out.find('\0') == std::string::npos ? out.size() : out.find('\0'));
    std::replace(out.begin(), out.end(), '\t', ' ');
    return out;
}

} // namespace replica::pipeline::display

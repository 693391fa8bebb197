// The KMS scan-out: connector, mode, CRTC and modesetting strategy; the first frame's modeset and
// each later frame's page flip.
#include <cerrno>
#include <cstring>
#include <vector>

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>
#include <xf86drm.h>

#include <platform/logging.h>
#include <platform/output/kms_scanout.h>

namespace replica::platform {

std::uint32_t propertyId(int fd, std::uint32_t object, std::uint32_t type, const char* name)
{
    drmModeObjectProperties* props = drmModeObjectGetProperties(fd, object, type);
    if (props == nullptr) {
        return 0;
    }
    std::uint32_t id = 0;
    for (std::uint32_t i = 0; i < props->count_props && id == 0; ++i) {
        drmModePropertyRes* p = drmModeGetProperty(fd, props->props[i]);
        if (p != nullptr) {
            if (std::strcmp(p->name, name) == 0) {
                id = p->prop_id;
            }
            drmModeFreeProperty(p);
        }
    }
    drmModeFreeObjectProperties(props);
    return id;
}

std::optional<std::uint64_t>
propertyValue(int fd, std::uint32_t object, std::uint32_t type, const char* name)
{
    drmModeObjectProperties* props = drmModeObjectGetProperties(fd, object, type);
    if (props == nullptr) {
        return std::nullopt;
    }
    std::optional<std::uint64_t> value;
    for (std::uint32_t i = 0; i < props->count_props && !value; ++i) {
        drmModePropertyRes* p = drmModeGetProperty(fd, props->props[i]);
        if (p != nullptr) {
            if (std::strcmp(p->name, name) == 0) {
                value = props->prop_values[i];
            }
            drmModeFreeProperty(p);
        }
    }
    drmModeFreeObjectProperties(props);
    return value;
}

namespace {

// The physical size in the connector's EDID blob, else what the kernel took from it.
std::optional<SizeMm> connectorPhysicalSize(int fd, const drmModeConnector& c)
{
    if (auto blobId = propertyValue(fd, c.connector_id, DRM_MODE_OBJECT_CONNECTOR, "EDID");
        blobId && *blobId != 0) {
        drmModePropertyBlobRes* blob =
                drmModeGetPropertyBlob(fd, static_cast<std::uint32_t>(*blobId));
        if (blob != nullptr) {
            auto size =
                    edidPhysicalSize({static_cast<const std::uint8_t*>(blob->data), blob->length});
            drmModeFreePropertyBlob(blob);
            if (size) {
                return size;
            }
        }
    }
    if (c.mmWidth > 0 && c.mmHeight > 0) {
        return SizeMm{static_cast<double>(c.mmWidth), static_cast<double>(c.mmHeight)};
    }
    return std::nullopt;
}

struct FreeResources {
    void operator()(drmModeRes* r) const { drmModeFreeResources(r); }
};
struct FreeConnector {
    void operator()(drmModeConnector* c) const { drmModeFreeConnector(c); }
};

} // namespace

KmsScanout::KmsScanout(int fd, std::string device)
{
    pipe_.fd = fd;
    pipe_.device = std::move(device);
}

KmsScanout::~KmsScanout()
{
    restore();
    if (saved_ != nullptr) {
        drmModeFreeCrtc(saved_);
    }
    modeset_.reset(); // its mode blob goes before the card's fd
    close(pipe_.fd);
}

Expected<void> KmsScanout::init(const KmsOptions& o)
{
    auto request = parseModeRequest(o.mode);
    if (!request) {
        return tl::unexpected(request.error());
    }
    std::unique_ptr<drmModeRes, FreeResources> res(drmModeGetResources(pipe_.fd));
    if (res == nullptr) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{} has no KMS resources (a render-only node?); use "
                                     "/dev/dri/cardN",
                                     pipe_.device));
    }
    auto chosen = pickConnector(*res, o);
    if (!chosen) {
        return tl::unexpected(chosen.error());
    }
    const std::unique_ptr<drmModeConnector, FreeConnector> connector(*chosen);
    if (auto ok = pickMode(*connector, *request, o); !ok) {
        return ok;
    }
    pickCrtc(*res, *connector);
    if (pipe_.crtcId == 0) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{}: no CRTC can drive {}", pipe_.device, pipe_.label));
    }
    saved_ = drmModeGetCrtc(pipe_.fd, pipe_.crtcId);
    return pickModeset(o);
}

// The first connected connector with modes (the one named in the options, when named).
Expected<drmModeConnector*> KmsScanout::pickConnector(const drmModeRes& res, const KmsOptions& o)
{
    std::string seen;
    for (int i = 0; i < res.count_connectors; ++i) {
        drmModeConnector* c = drmModeGetConnector(pipe_.fd, res.connectors[i]);
        if (c == nullptr) {
            continue;
        }
        const char* type = drmModeGetConnectorTypeName(c->connector_type);
        const std::string name =
                fmt::format("{}-{}", type != nullptr ? type : "unknown", c->connector_type_id);
        seen += (seen.empty() ? "" : ", ") + name +
                (c->connection == DRM_MODE_CONNECTED ? " (connected)" : "");
        if (c->connection == DRM_MODE_CONNECTED && c->count_modes > 0 &&
            (o.connector.empty() || o.connector == name)) {
            pipe_.label = name;
            return c;
        }
        drmModeFreeConnector(c);
    }
    return makeError(ErrorCode::NotFound,
                     fmt::format("{}: no connected display{} (connectors: {}); check the "
                                 "cable and that the panel is on",
                                 pipe_.device, o.connector.empty() ? "" : " on " + o.connector,
                                 seen.empty() ? "none" : seen));
}

// The requested mode of the connector (or its preferred one), and its physical size.
Expected<void> KmsScanout::pickMode(const drmModeConnector& connector,
                                    const ModeRequest& request,
                                    const KmsOptions& o)
{
    std::vector<DisplayMode> modes;
    for (int m = 0; m < connector.count_modes; ++m) {
        const drmModeModeInfo& k = connector.modes[m];
        modes.push_back({k.hdisplay, k.vdisplay, static_cast<int>(k.vrefresh),
                         (k.type & DRM_MODE_TYPE_PREFERRED) != 0});
    }
    auto index = chooseMode(modes, request);
    if (!index && o.modeOrPreferred) {
        logger("output")->info("kms {} {}: no mode {}; taking the preferred one", pipe_.device,
                               pipe_.label, o.mode);
        index = chooseMode(modes, ModeRequest{});
    }
    if (!index) {
        return makeError(index.error().code, fmt::format("{} {}: {}", pipe_.device, pipe_.label,
                                                         index.error().message));
    }
    pipe_.mode = connector.modes[*index];
    pipe_.connectorId = connector.connector_id;
    edid_ = connectorPhysicalSize(pipe_.fd, connector);
    return {};
}

// A CRTC that one of the connector's encoders can drive.
void KmsScanout::pickCrtc(const drmModeRes& res, const drmModeConnector& connector)
{
    for (int e = 0; e < connector.count_encoders && pipe_.crtcId == 0; ++e) {
        drmModeEncoder* enc = drmModeGetEncoder(pipe_.fd, connector.encoders[e]);
        if (enc == nullptr) {
            continue;
        }
        for (int c = 0; c < res.count_crtcs; ++c) {
            if ((enc->possible_crtcs & (1u << c)) != 0) {
                pipe_.crtcId = res.crtcs[c];
                pipe_.crtcIndex = c;
                break;
            }
        }
        drmModeFreeEncoder(enc);
    }
}

// Atomic modesetting where the driver offers it (unless o.modeset is "legacy"), else legacy.
Expected<void> KmsScanout::pickModeset(const KmsOptions& o)
{
    const std::string& modeset = o.modeset;
    if (modeset != "auto" && modeset != "atomic" && modeset != "legacy") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("KMS modeset '{}': expected auto, atomic or legacy", modeset));
    }
    if (modeset != "legacy") {
        std::string why;
        modeset_ = createAtomicModeset(pipe_, why);
        if (modeset_ == nullptr) {
            if (modeset == "atomic") {
                return makeError(ErrorCode::Unsupported,
                                 fmt::format("{}: no atomic modesetting ({})", pipe_.device, why));
            }
            logger("output")->info("kms {}: legacy modesetting ({})", pipe_.device, why);
        }
    }
    if (modeset_ == nullptr) {
        modeset_ = createLegacyModeset(pipe_);
    }
    return {};
}

Expected<void> KmsScanout::setMode(std::uint32_t fb)
{
    if (modeset_->atomic()) {
        auto ok = modeset_->setMode(fb);
        if (ok) {
            modeSet_ = true;
            logger("output")->info("kms {}: first frame on screen", describe());
            return {};
        }
        // A driver that lists the properties but refuses the commit: legacy calls.
        logger("output")->warn("kms {}: atomic modeset failed ({}); using legacy modesetting",
                               pipe_.device, ok.error().message);
        modeset_ = createLegacyModeset(pipe_);
    }
    if (auto ok = modeset_->setMode(fb); !ok) {
        return ok;
    }
    modeSet_ = true;
    logger("output")->info("kms {}: first frame on screen", describe());
    return {};
}

Expected<void> KmsScanout::show(std::uint32_t fb)
{
    if (!modeSet_) {
        return setMode(fb);
    }
    flipped_ = false;
    if (auto ok = modeset_->flip(fb, this); !ok) {
        return ok;
    }
    drmEventContext ev{};
    ev.version = 2;
    ev.page_flip_handler = [](int, unsigned, unsigned, unsigned, void* self) {
        static_cast<KmsScanout*>(self)->flipped_ = true;
    };
    // A display refreshes at least every 100 ms; a second without the event is a fault.
    for (int waited = 0; !flipped_ && waited < 1000; waited += 100) {
        pollfd p{pipe_.fd, POLLIN, 0};
        if (poll(&p, 1, 100) > 0) {
            drmHandleEvent(pipe_.fd, &ev);
        }
    }
    if (!flipped_) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("{}: page flip on {} did not complete within 1 s",
                                     pipe_.device, pipe_.label));
    }
    return {};
}

void KmsScanout::restore()
{
    if (saved_ != nullptr && modeSet_ && saved_->buffer_id != 0) {
        drmModeSetCrtc(pipe_.fd, saved_->crtc_id, saved_->buffer_id, saved_->x, saved_->y,
                       &pipe_.connectorId, 1, &saved_->mode);
    }
    modeSet_ = false;
}

DisplayInfo KmsScanout::info() const
{
    return {pipe_.mode.hdisplay, pipe_.mode.vdisplay, edid_, pipe_.label};
}

std::string KmsScanout::describe() const
{
    return fmt::format("{} {} {}x{}@{} {}", pipe_.device, pipe_.label, pipe_.mode.hdisplay,
                       pipe_.mode.vdisplay, pipe_.mode.vrefresh,
                       modeset_ != nullptr && modeset_->atomic() ? "atomic" : "legacy");
}

} // namespace replica::platform

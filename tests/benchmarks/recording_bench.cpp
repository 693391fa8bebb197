// Recording costs: write throughput (MB/s, samples/s), the CPU cost of recording the live sensor
// rates as a fraction of one core, and sensor-only replay speed as a multiple of real time. Prints
// figures; never fails on timing.
#include <chrono>
#include <ctime>
#include <filesystem>
#include <random>
#include <thread>

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <platform/appliance.h>
#include <recordings/recording.h>

namespace {

using namespace replica;
using Clock = std::chrono::steady_clock;

// The appliance's live rates (Hz).
constexpr int kSpectrometerHz = 5, kTrackerHz = 120, kAccelHz = 100, kFrameHz = 60;

std::filesystem::path benchFile(const char* name)
{
    return std::filesystem::temp_directory_path() /
           (std::string("replica-bench-") + name + "-" + std::to_string(::getpid()) + ".mcap");
}

double cpuSeconds()
{
    timespec ts{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Realistic samples: a 2048-pixel spectrum with shot noise (compresses like a real one), a moving
// eye, a slightly tilting gravity vector.
struct SampleMaker {
    std::mt19937 rng{7};
    std::normal_distribution<double> noise{0.0, 1.0};

    hal::SpectrumSample spectrum(std::uint32_t seq, std::int64_t t)
    {
        hal::SpectrumSample s;
        s.timestampNs = t;
        s.sequence = seq;
        s.integrationTimeUs = 100'000;
        s.counts.resize(2048);
        for (std::size_t p = 0; p < s.counts.size(); ++p) {
            const double mean =
                    1500.0 + 30000.0 * std::exp(-std::pow((double(p) - 900.0) / 400.0, 2));
            s.counts[p] = static_cast<std::uint16_t>(
                    std::clamp(mean + std::sqrt(mean) * noise(rng), 0.0, 65535.0));
        }
        s.wavelengthCoeffs = {339.2, 0.3797, -1.62e-5, -1.3e-10};
        s.nonlinearityCoeffs = {1.0, -2e-6, 0, 0, 0, 0, 0, 0};
        return s;
    }
    hal::PoseSample pose(std::uint32_t seq, std::int64_t t)
    {
        const double s = 1e-9 * static_cast<double>(t);
        return {t,
                seq,
                {0.3 * std::sin(s) + 1e-4 * noise(rng), 0.05 * std::cos(2 * s), 0.6},
                true,
                nullptr};
    }
    hal::AccelSample accel(std::uint32_t seq, std::int64_t t)
    {
        return {t,
                seq,
                {0.01 * noise(rng), -8.14 + 0.01 * noise(rng), -5.43 + 0.01 * noise(rng)},
                nullptr};
    }
};

// Feeds `seconds` of session at the live rates into `w`, in time order. With `realTime`, each
// sample is written when it is due on the wall clock (as the loop would); otherwise at once.
std::uint64_t feed(recordings::RecordingWriter& w, int seconds, bool realTime)
{
    SampleMaker make;
    const std::int64_t endNs = std::int64_t{seconds} * 1'000'000'000;
    const auto start = Clock::now();
    std::uint32_t nS = 0, nT = 0, nA = 0, nF = 0;
    std::uint64_t written = 0;
    auto due = [](std::uint32_t n, int hz) {
        return static_cast<std::int64_t>(n) * 1'000'000'000 / hz;
    };
    for (;;) {
        const std::int64_t t = std::min({due(nS, kSpectrometerHz), due(nT, kTrackerHz),
                                         due(nA, kAccelHz), due(nF, kFrameHz)});
        if (t >= endNs) {
            break;
        }
        if (realTime) {
            std::this_thread::sleep_until(start + std::chrono::nanoseconds(t));
        }
        if (t == due(nS, kSpectrometerHz)) {
            w.write(make.spectrum(nS++, t));
            ++written;
        }
        if (t == due(nT, kTrackerHz)) {
            w.write(make.pose(nT++, t));
            ++written;
        }
        if (t == due(nA, kAccelHz)) {
            w.write(make.accel(nA++, t));
            ++written;
        }
        if (t == due(nF, kFrameHz)) {
            recordings::FrameRecord f{nF, t, {}};
            f.setSequence(recordings::spectrometerKind(),
                          nS ? std::optional(nS - 1) : std::nullopt);
            f.setSequence(recordings::trackerKind(), nT - 1);
            f.setSequence(recordings::accelKind(), nA ? std::optional(nA - 1) : std::nullopt);
            w.write(f);
            ++nF;
            ++written;
        }
    }
    return written;
}

recordings::SessionInfo session()
{
    recordings::SessionInfo s;
    s.softwareVersion = "replica bench";
    s.configJson = platform::RunConfig{}.toJson();
    s.wallClockStartNs = 1'700'000'000'000'000'000;
    return s;
}

// Everything from create() to a closed, synced file: samples/s and MB/s of file written.
void BM_WriteThroughput(benchmark::State& st)
{
    const int seconds = static_cast<int>(st.range(0));
    const auto path = benchFile("throughput");
    std::uint64_t samples = 0, bytes = 0, dropped = 0;
    double wall = 0.0;
    for (auto _ : st) {
        recordings::WriterOptions options;
        options.queueCapacity = 1 << 20; // measure the writer, not the queue bound
        const auto t0 = Clock::now();
        auto w = recordings::RecordingWriter::create(path, session(), options);
        if (!w) {
            st.SkipWithError(w.error().message.c_str());
            return;
        }
        samples += feed(**w, seconds, false);
        (void)(*w)->close();
        wall += std::chrono::duration<double>(Clock::now() - t0).count();
        bytes += (*w)->stats().bytes;
        dropped += (*w)->stats().dropped;
    }
    st.counters["samples_per_s"] = static_cast<double>(samples) / wall;
    st.counters["MB_per_s"] = static_cast<double>(bytes) / wall / 1e6;
    st.counters["file_MB_per_session_min"] =
            static_cast<double>(bytes) / static_cast<double>(st.iterations()) / seconds * 60 / 1e6;
    st.counters["dropped"] = static_cast<double>(dropped);
    std::filesystem::remove(path);
}
BENCHMARK(BM_WriteThroughput)->Arg(30)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The live rates in real time: process CPU time (writer thread, encoding, compression, syncs, and
// the producer's write() calls) over wall time, i.e. the fraction of one core recording costs.
void BM_LiveRateCpu(benchmark::State& st)
{
    const int seconds = static_cast<int>(st.range(0));
    const auto path = benchFile("live");
    double cpu = 0.0, wall = 0.0;
    std::uint64_t dropped = 0, chunks = 0;
    for (auto _ : st) {
        auto w = recordings::RecordingWriter::create(path, session());
        if (!w) {
            st.SkipWithError(w.error().message.c_str());
            return;
        }
        const double c0 = cpuSeconds();
        const auto t0 = Clock::now();
        feed(**w, seconds, true);
        (void)(*w)->close();
        cpu += cpuSeconds() - c0;
        wall += std::chrono::duration<double>(Clock::now() - t0).count();
        dropped += (*w)->stats().dropped;
        chunks += (*w)->stats().chunks;
    }
    st.counters["core_fraction"] = cpu / wall;
    st.counters["dropped"] = static_cast<double>(dropped);
    st.counters["chunks_per_s"] = static_cast<double>(chunks) / wall;
    std::filesystem::remove(path);
}
BENCHMARK(BM_LiveRateCpu)->Arg(5)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// The lamp selector's channel: what one message costs the writer (encode, compress, write) and the
// file. A booth's switch turns a few times per session, so the channel's share is this times the
// turns per second; the appliance's other streams write 285 messages per second.
void BM_LampSelectorMessages(benchmark::State& st)
{
    const auto count = static_cast<std::uint32_t>(st.range(0));
    const auto path = benchFile("lamp");
    double wall = 0.0;
    std::uint64_t bytes = 0, empty = 0;
    for (auto _ : st) {
        recordings::WriterOptions options;
        options.queueCapacity = 1 << 20;
        // The same session with no messages: what the file costs without the channel's traffic.
        {
            auto w0 = recordings::RecordingWriter::create(path, session(), options);
            if (!w0) {
                st.SkipWithError(w0.error().message.c_str());
                return;
            }
            (void)(*w0)->close();
            empty += (*w0)->stats().bytes;
        }
        const auto t0 = Clock::now();
        auto w = recordings::RecordingWriter::create(path, session(), options);
        if (!w) {
            st.SkipWithError(w.error().message.c_str());
            return;
        }
        for (std::uint32_t i = 0; i < count; ++i) {
            hal::LampSample l;
            l.timestampNs = std::int64_t{i} * 2'000'000'000 + 33'000'000 + (i * 7919) % 6'000'000;
            l.sequence = i;
            l.lineCount = 3;
            l.lamp = static_cast<int>(i % 3);
            l.lineLevels = 1u << (i % 3);
            (*w)->write(l);
        }
        (void)(*w)->close();
        wall += std::chrono::duration<double>(Clock::now() - t0).count();
        bytes += (*w)->stats().bytes;
    }
    const double n = static_cast<double>(count) * static_cast<double>(st.iterations());
    st.counters["us_per_message"] = wall / n * 1e6;
    st.counters["file_bytes_per_message"] = static_cast<double>(bytes - empty) / n;
    std::filesystem::remove(path);
}
BENCHMARK(BM_LampSelectorMessages)
        ->Arg(100000)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(3);

// Sensor-only replay: read and decode the recording, then poll the replay sources for every
// frame tick, as the loop does before rendering. Session seconds per wall second.
void BM_ReplaySensorsOnly(benchmark::State& st)
{
    const int seconds = static_cast<int>(st.range(0));
    const auto path = benchFile("replay");
    {
        recordings::WriterOptions options;
        options.queueCapacity = 1 << 20;
        auto w = recordings::RecordingWriter::create(path, session(), options);
        if (!w) {
            st.SkipWithError(w.error().message.c_str());
            return;
        }
        feed(**w, seconds, false);
        (void)(*w)->close();
    }
    double wall = 0.0;
    std::size_t consumed = 0;
    for (auto _ : st) {
        const auto t0 = Clock::now();
        auto rec = recordings::readRecording(path);
        if (!rec) {
            st.SkipWithError(rec.error().message.c_str());
            return;
        }
        auto sources = platform::makeReplaySources(*rec);
        std::vector<hal::SpectrumSample> spectra;
        std::vector<hal::PoseSample> poses;
        std::vector<hal::AccelSample> accel;
        for (const auto& f : rec->frames) {
            sources.get(recordings::spectrometerKind())->poll(f.tickNs, spectra);
            sources.get(recordings::trackerKind())->poll(f.tickNs, poses);
            sources.get(recordings::accelKind())->poll(f.tickNs, accel);
        }
        consumed += spectra.size() + poses.size() + accel.size();
        benchmark::DoNotOptimize(consumed);
        wall += std::chrono::duration<double>(Clock::now() - t0).count();
    }
    st.counters["x_real_time"] =
            static_cast<double>(seconds) * static_cast<double>(st.iterations()) / wall;
    st.counters["samples"] = static_cast<double>(consumed) / static_cast<double>(st.iterations());
    std::filesystem::remove(path);
}
BENCHMARK(BM_ReplaySensorsOnly)
        ->Arg(60)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(3);

} // namespace

BENCHMARK_MAIN();

// Tests of `bayeslight compare` (SPEC.md section 4): its outputs on a tiny scene (curves.csv rows for every
// pass, summary.md numbers equal to the CSV's last rows, a well-formed SVG with one path per sampler, images),
// its exit statuses, and the pieces it is built from (time to a target error, the plot writer, the ramp).
#include "compare.h"
#include "metrics.h"
#include "render.h"
#include "error_image.h"
#include "image_io.h"
#include "svg_plot.h"
#include "test_util.h"

#include <catch2/catch.hpp>
#include <stb_image.h>

#include <array>
#include <cctype>
#include <cmath>
#include <map>

using namespace bl;
using namespace bl::test;

namespace {

// A tiny scene (a floor under a small lamp, 16x12 pixels, depth 2) and a 16 spp uniform reference of it.
struct compare_scene {
  temp_dir dir;
  std::string json, ref;
  compare_scene() {
    write_text(dir / "box.obj",
               "mtllib box.mtl\n"
               "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
               "v -0.2 1 -0.2\nv 0.2 1 -0.2\nv 0.2 1 0.2\nv -0.2 1 0.2\n"
               "v 0.5 0.8 -0.2\nv 0.7 0.8 -0.2\nv 0.7 0.8 0.2\nv 0.5 0.8 0.2\n"
               "usemtl floor\nf 1 4 3 2\n"
               "usemtl lamp\nf 5 6 7 8\n"
               "usemtl dim\nf 9 10 11 12\n");
    write_text(dir / "box.mtl",
               "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\nnewmtl dim\nKd 0 0 0\nKe 0.5 0.2 0.1\n");
    json = dir / "scene.json";
    write_text(json, "{\"mesh\": \"box.obj\", \"camera\": {\"eye\": [0, 0.5, 2], \"target\": [0, 0, 0]},"
                     " \"image\": {\"width\": 16, \"height\": 12}, \"render\": {\"spp\": 2, \"max_depth\": 2}}");
    ref = dir / "ref.exr";
    run_result r = run_bayeslight("render " + json + " --sampler uniform --spp 16 --seed 99 -o " + ref + " --quiet");
    INFO(r.output);
    REQUIRE(r.status == 0);
  }
};

// One row of curves.csv.
struct csv_row {
  std::string sampler;
  int run = 0, pass = 0, spp = 0;
  unsigned long long seed = 0;
  double seconds = 0, relmse = 0, mse = 0;
};

// The rows of curves.csv (the header is checked).
std::vector<csv_row> read_curves(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  CHECK(line == "sampler,pass,spp,seconds,relmse,mse,run,seed");  // (--log's columns first)
  std::vector<csv_row> rows;
  while (std::getline(f, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    REQUIRE(c.size() == 8);
    rows.push_back({c[0], std::stoi(c[6]), std::stoi(c[1]), std::stoi(c[2]), std::stoull(c[7]), std::stod(c[3]),
                    std::stod(c[4]), std::stod(c[5])});
  }
  return rows;
}

// Cells of the data rows of summary.md's table, by sampler (cells trimmed; the sampler cell is the key).
std::map<std::string, std::vector<std::string>> read_summary_table(const std::string& text) {
  std::map<std::string, std::vector<std::string>> table;
  std::stringstream ss(text);
  std::string line;
  while (std::getline(ss, line)) {
    if (line.rfind("| ", 0) != 0 || line.rfind("| sampler ", 0) == 0) continue;
    std::vector<std::string> cells;
    size_t pos = 1;
    while (pos < line.size()) {
      size_t bar = line.find('|', pos);
      if (bar == std::string::npos) break;
      std::string cell = line.substr(pos, bar - pos);
      cell.erase(0, cell.find_first_not_of(' '));
      cell.erase(cell.find_last_not_of(' ') + 1);
      cells.push_back(cell);
      pos = bar + 1;
    }
    REQUIRE((cells.size() == 7 || cells.size() == 8));  // (equal time: the image's relMSE too)
    table[cells[0]] = cells;
  }
  return table;
}

// Whole content of a file.
std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Occurrences of `needle` in `text`.
int count_of(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) n++;
  return n;
}

// Minimal XML well-formedness: one root element, balanced and matching tags, quoted attributes without '<',
// entity references among the predefined ones or numeric; declarations, comments and CDATA are skipped.
// Returns "" when well-formed, else what is wrong.
std::string xml_problem(const std::string& s) {
  std::vector<std::string> open;
  int roots = 0;
  auto name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == ':' || c == '.';
  };
  auto check_entities = [](const std::string& t) -> bool {
    for (size_t p = t.find('&'); p != std::string::npos; p = t.find('&', p + 1)) {
      size_t semi = t.find(';', p);
      if (semi == std::string::npos) return false;
      std::string e = t.substr(p + 1, semi - p - 1);
      bool named = e == "amp" || e == "lt" || e == "gt" || e == "quot" || e == "apos";
      if (!named && (e.empty() || e[0] != '#')) return false;
    }
    return true;
  };
  size_t i = 0;
  while (i < s.size()) {
    if (s[i] != '<') {
      size_t next = s.find('<', i);
      std::string text = s.substr(i, next == std::string::npos ? std::string::npos : next - i);
      if (open.empty() && text.find_first_not_of(" \t\r\n") != std::string::npos) return "text outside the root";
      if (!check_entities(text)) return "bad entity in text";
      if (next == std::string::npos) break;
      i = next;
      continue;
    }
    if (s.compare(i, 4, "<!--") == 0) {
      size_t e = s.find("-->", i);
      if (e == std::string::npos) return "unterminated comment";
      i = e + 3;
      continue;
    }
    if (s.compare(i, 2, "<?") == 0) {
      size_t e = s.find("?>", i);
      if (e == std::string::npos) return "unterminated declaration";
      i = e + 2;
      continue;
    }
    if (s.compare(i, 9, "<![CDATA[") == 0) {
      size_t e = s.find("]]>", i);
      if (e == std::string::npos) return "unterminated CDATA";
      i = e + 3;
      continue;
    }
    bool closing = s.compare(i, 2, "</") == 0;
    size_t p = i + (closing ? 2 : 1), start = p;
    while (p < s.size() && name_char(s[p])) p++;
    std::string name = s.substr(start, p - start);
    if (name.empty()) return "tag without a name at " + std::to_string(i);
    if (closing) {
      while (p < s.size() && std::isspace(static_cast<unsigned char>(s[p]))) p++;
      if (p >= s.size() || s[p] != '>') return "bad end tag " + name;
      if (open.empty() || open.back() != name) return "end tag " + name + " does not match";
      open.pop_back();
      i = p + 1;
      continue;
    }
    // Attributes: name="value" or name='value'.
    for (;;) {
      while (p < s.size() && std::isspace(static_cast<unsigned char>(s[p]))) p++;
      if (p >= s.size()) return "unterminated tag " + name;
      if (s[p] == '>' || s.compare(p, 2, "/>") == 0) break;
      size_t a = p;
      while (p < s.size() && name_char(s[p])) p++;
      if (p == a) return "bad attribute in " + name;
      while (p < s.size() && std::isspace(static_cast<unsigned char>(s[p]))) p++;
      if (p >= s.size() || s[p] != '=') return "attribute without value in " + name;
      p++;
      while (p < s.size() && std::isspace(static_cast<unsigned char>(s[p]))) p++;
      if (p >= s.size() || (s[p] != '"' && s[p] != '\'')) return "unquoted attribute in " + name;
      char q = s[p];
      size_t e = s.find(q, p + 1);
      if (e == std::string::npos) return "unterminated attribute in " + name;
      std::string value = s.substr(p + 1, e - p - 1);
      if (value.find('<') != std::string::npos || !check_entities(value)) return "bad attribute value in " + name;
      p = e + 1;
    }
    if (open.empty()) roots++;
    if (roots > 1) return "more than one root element";
    if (s[p] == '>') {
      open.push_back(name);
      i = p + 1;
    } else {
      i = p + 2;
    }
  }
  if (!open.empty()) return "unclosed element " + open.back();
  if (roots != 1) return "no root element";
  return "";
}

// Whether xmllint is on this machine.
bool have_xmllint() { return std::system("command -v xmllint >/dev/null 2>&1") == 0; }

// Checks everything a comparison wrote into out: files, CSV rows per sampler and run, summary = CSV's last rows
// (relMSE: at exactly the budget at equal time, between the passes around it).
// budget: the --time of an equal-time comparison (0: equal spp).
void check_outputs(const std::string& out, const std::vector<std::string>& samplers, int runs, double budget) {
  const bool equal_time = budget > 0;
  for (const char* name : {"curves.csv", "error_vs_time.svg", "summary.md"})
    CHECK(std::filesystem::exists(out + "/" + std::string(name)));
  std::vector<csv_row> rows = read_curves(out + "/curves.csv");
  std::string summary = slurp(out + "/summary.md");
  INFO(summary);
  auto table = read_summary_table(summary);
  REQUIRE(table.size() == samplers.size());
  double base_relmse = 0;
  for (size_t k = 0; k < samplers.size(); k++) {
    const std::string& s = samplers[k];
    // Rows of every run, passes numbered 1, 2, ... with growing spp and time.
    std::vector<const csv_row*> last;
    std::vector<double> at_end;  // each run's relMSE at the end: at exactly the budget at equal time
    for (int run = 1; run <= runs; run++) {
      const csv_row* prev = nullptr;
      const csv_row* before = nullptr;  // the last pass before the budget, and the first at or after it
      const csv_row* after = nullptr;
      for (const csv_row& r : rows) {
        if (r.sampler != s || r.run != run) continue;
        CHECK(r.pass == (prev ? prev->pass + 1 : 1));
        if (prev) CHECK(r.spp > prev->spp);
        if (prev) CHECK(r.seconds >= prev->seconds);
        CHECK(r.relmse > 0);
        CHECK(r.mse > 0);
        prev = &r;
        if (r.seconds < budget) before = &r;
        else if (!after) after = &r;
      }
      REQUIRE(prev != nullptr);
      last.push_back(prev);
      double e = prev->relmse;
      if (equal_time && after && before) {
        double f = std::log(budget / before->seconds) / std::log(after->seconds / before->seconds);
        e = std::exp(std::log(before->relmse) + f * std::log(after->relmse / before->relmse));
      } else if (equal_time && after) {
        e = after->relmse;
      }
      at_end.push_back(e);
    }
    // The summary's numbers are those of the runs' last rows (means over runs).
    const std::vector<std::string>& cells = table.at(s);
    double relmse = 0, seconds = 0;
    for (const csv_row* r : last) seconds += r->seconds / runs;
    for (double e : at_end) relmse += e / runs;
    CHECK(std::stoi(cells[1]) == last[0]->spp);
    CHECK(std::stod(cells[2]) == Approx(seconds).epsilon(1e-3).margin(2e-6));
    CHECK(std::stod(cells[3]) == Approx(relmse).epsilon(2e-4));
    if (runs > 1) {
      double var = 0;
      for (double e : at_end) var += (e - relmse) * (e - relmse) / (runs - 1);
      size_t pm = cells[3].find("\xc2\xb1");
      REQUIRE(pm != std::string::npos);
      CHECK(std::stod(cells[3].substr(pm + 2)) == Approx(std::sqrt(var)).epsilon(1e-2));
    }
    // Time to the first sampler's final relMSE: the first sampler reaches it by its last pass at the latest.
    if (cells[5] != "\xe2\x80\x94") {
      CHECK(std::stod(cells[5]) > 0);
      CHECK(std::stod(cells[5]) <= seconds * 1.001 + 2e-6);
    }
    if (k == 0) {
      base_relmse = relmse;
      CHECK(cells[4] == "1.00");
      CHECK(cells[5] != "\xe2\x80\x94");
    } else if (equal_time) {
      CHECK(std::stod(cells[4]) == Approx(base_relmse / relmse).epsilon(1e-2));
    }
    // The render and its false-colour error image.
    image_data img = read_image(out + "/" + s + ".exr");
    CHECK(img.width == 16);
    CHECK(img.height == 12);
    std::string png = slurp(out + "/" + s + "_error.png");
    CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
    // The render again as 8-bit sRGB: the bytes render -o would write for the same pixels.
    const std::string own = out + "/" + s + "_own.png";
    write_image(own, img);
    CHECK(slurp(out + "/" + s + ".png") == slurp(own));
    std::filesystem::remove(own);
  }
  // The plot: well-formed XML, one path per sampler, the dashed guide, every sampler in the legend.
  std::string svg = slurp(out + "/error_vs_time.svg");
  CHECK(xml_problem(svg) == "");
  CHECK(count_of(svg, "<path") + count_of(svg, "<polyline") == int(samplers.size()));
  CHECK(count_of(svg, "stroke-dasharray") >= 1);
  for (const std::string& s : samplers) CHECK(svg.find(">" + s + "</text>") != std::string::npos);
  if (have_xmllint()) CHECK(std::system(("xmllint --noout " + out + "/error_vs_time.svg").c_str()) == 0);
}

}  // namespace

TEST_CASE("compare at equal spp writes curves summary plot and images", "[compare]") {
  compare_scene s;
  std::string out = s.dir / "out" + "/run";  // neither exists yet: compare creates both, as mkdir -p
  run_result r = run_bayeslight("compare " + s.json + " --reference " + s.ref +
                                " --spp 4 --samplers uniform,power,bvh --out " + out + " --threads 2 --quiet");
  INFO(r.output);
  REQUIRE(r.status == 0);
  check_outputs(out, {"uniform", "power", "bvh"}, 1, 0);
  std::vector<csv_row> rows = read_curves(out + "/curves.csv");
  CHECK(rows.size() == 12);  // 4 passes of 1 spp for each sampler
  for (const csv_row& row : rows) CHECK(row.seed == 0);  // the scene's seed
  std::string summary = slurp(out + "/summary.md");
  CHECK(summary.find("reference: " + s.ref) != std::string::npos);
  CHECK(summary.find("Equal samples: 4 spp") != std::string::npos);
  // No temporary files left behind.
  for (auto& e : std::filesystem::directory_iterator(out))
    CHECK(e.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("compare names the images an earlier comparison left in its folder", "[compare]") {
  // A second comparison of fewer samplers into the same folder left the others' images beside a summary that does
  // not list them, without a word (a review); they are named, and kept.
  compare_scene s;
  std::string out = s.dir / "out";
  std::string args = "compare " + s.json + " --reference " + s.ref + " --spp 2 --out " + out + " --threads 1 --quiet";
  REQUIRE(run_bayeslight(args + " --samplers uniform,power,bvh").status == 0);
  run_result r = run_bayeslight(args + " --samplers bvh,uniform");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("compare: warning: " + out + " also holds power.exr, power.png, power_error.png from an earlier "
                      "comparison (not part of this one)") != std::string::npos);
  CHECK(std::filesystem::exists(out + "/power.exr"));
  CHECK(slurp(out + "/summary.md").find(" | 1 thread\n") != std::string::npos);  // (it said "1 threads")
  r = run_bayeslight(args + " --samplers power,bvh,uniform");
  CHECK(r.output.find("warning") == std::string::npos);
}

TEST_CASE("compare interrupted before any pass keeps an earlier comparison's files", "[compare]") {
  // It rewrote curves.csv (header only), summary.md and the plot over the earlier results (a review). A signal 4 s
  // in reaches bayes's oracle warm-up (endless; set-up takes milliseconds, under ASan on a loaded machine about a
  // second): no pass is complete.
  compare_scene s;
  std::string out = s.dir / "out";
  std::string args = "compare " + s.json + " --reference " + s.ref + " --samplers bayes,uniform --out " + out +
                     " --threads 1 --quiet";
  REQUIRE(run_bayeslight(args + " --spp 2").status == 0);
  std::map<std::string, std::string> before;
  for (auto& e : std::filesystem::directory_iterator(out)) before[e.path().string()] = slurp(e.path().string());
  REQUIRE(before.size() >= 5);
  run_result r;
  FILE* p = popen(("timeout --preserve-status -s INT 4 " + std::string(BAYESLIGHT_BINARY) + " " + args +
                   " --spp 2 --bayes-oracle 100000000 2>&1").c_str(), "r");
  REQUIRE(p);
  char buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) r.output.append(buf, n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  INFO(r.output);
  CHECK(r.status == 130);
  CHECK(r.output.find("interrupted before the first pass; nothing written") != std::string::npos);
  std::map<std::string, std::string> after;
  for (auto& e : std::filesystem::directory_iterator(out)) after[e.path().string()] = slurp(e.path().string());
  CHECK(after == before);
  // A folder the interrupted comparison created is not left behind, empty (a review).
  const std::string fresh = s.dir / "fresh/a/b";
  st = std::system(("timeout --preserve-status -s INT 4 " + std::string(BAYESLIGHT_BINARY) + " compare " + s.json +
                    " --reference " + s.ref + " --samplers bayes --out " + fresh +
                    " --threads 1 --quiet --spp 2 --bayes-oracle 100000000 2>/dev/null").c_str());
  CHECK(WIFEXITED(st));
  CHECK(WEXITSTATUS(st) == 130);
  CHECK(!std::filesystem::exists(s.dir / "fresh"));
  // Cut short after uniform's passes, in bayes's warm-up: the summary covers uniform, and the earlier bayes images
  // (which it does not describe) are gone.
  REQUIRE(std::filesystem::exists(out + "/bayes.exr"));
  p = popen(("timeout --preserve-status -s INT 4 " + std::string(BAYESLIGHT_BINARY) + " compare " + s.json +
             " --reference " + s.ref + " --samplers uniform,bayes --out " + out +
             " --threads 1 --quiet --spp 2 --bayes-oracle 100000000 2>&1").c_str(), "r");
  REQUIRE(p);
  while (fread(buf, 1, sizeof buf, p) > 0) {}
  st = pclose(p);
  CHECK(WIFEXITED(st));
  CHECK(WEXITSTATUS(st) == 130);
  CHECK(std::filesystem::exists(out + "/uniform.exr"));
  CHECK(!std::filesystem::exists(out + "/bayes.exr"));
  CHECK(!std::filesystem::exists(out + "/bayes.png"));
  CHECK(!std::filesystem::exists(out + "/bayes_error.png"));
  CHECK(slurp(out + "/summary.md").find("Interrupted") != std::string::npos);
}

TEST_CASE("compare repeats runs with consecutive seeds and reports mean and deviation", "[compare]") {
  compare_scene s;
  std::string out = s.dir / "out";
  // (A blank after the comma, as a list is often written, is dropped: it was an unknown sampler " bayes".)
  run_result r = run_bayeslight("compare " + s.json + " --reference " + s.ref +
                                " --spp 3 --runs 3 --seed 7 --samplers 'power, bayes' --out " + out +
                                " --reference-note 'reference: 16 spp uniform, seed 99' --quiet");
  INFO(r.output);
  REQUIRE(r.status == 0);
  check_outputs(out, {"power", "bayes"}, 3, 0);
  std::vector<csv_row> rows = read_curves(out + "/curves.csv");
  CHECK(rows.size() == 2 * 3 * 3);
  for (const csv_row& row : rows) CHECK(row.seed == 7 + unsigned(row.run) - 1);
  std::string summary = slurp(out + "/summary.md");
  CHECK(summary.find("reference: 16 spp uniform, seed 99") != std::string::npos);
  // A run's image equals a plain render with the same seed and spp (compare renders exactly like render).
  REQUIRE(run_bayeslight("render " + s.json + " --sampler bayes --spp 3 --seed 7 -o " + (s.dir / "b.exr") + " --quiet")
              .status == 0);
  CHECK(bit_identical(read_image(out + "/bayes.exr"), read_image(s.dir / "b.exr")));
  CHECK(summary.find("3 runs (seeds 7 to 9)") != std::string::npos);
  // Consecutive seeds from the largest wrap to 0, and the summary says so (it read "seeds 18446744073709551615 to 0").
  r = run_bayeslight("compare " + s.json + " --reference " + s.ref + " --spp 1 --runs 2 --seed 18446744073709551615 "
                     "--samplers power --out " + out + " --quiet");
  REQUIRE(r.status == 0);
  CHECK(slurp(out + "/summary.md").find("(seeds 18446744073709551615 to 0, wrapping past 2^64 - 1 to 0)") !=
        std::string::npos);
}

TEST_CASE("compare at equal time gives every sampler the same budget", "[compare]") {
  // (0.25 s, not 0.05: a first pass that ends after the budget leaves no relMSE at it, hence no speed-up, only a
  // dash; under ASan at load 6 on 2 cores first passes ended at up to 9 ms, and a stall of tens of ms is possible.)
  compare_scene s;
  std::string out = s.dir / "out";
  run_result r = run_bayeslight("compare " + s.json + " --reference " + s.ref +
                                " --time 0.25 --samplers bound,uniform --out " + out + " --quiet");
  INFO(r.output);
  REQUIRE(r.status == 0);
  check_outputs(out, {"bound", "uniform"}, 1, 0.25);
  for (const csv_row& row : read_curves(out + "/curves.csv")) CHECK(row.seconds > 0);
  std::map<std::string, double> final_seconds, final_relmse;
  std::map<std::string, int> final_spp, before_spp, passes;
  for (const csv_row& row : read_curves(out + "/curves.csv")) {
    final_seconds[row.sampler] = row.seconds, final_relmse[row.sampler] = row.relmse;
    before_spp[row.sampler] = final_spp[row.sampler];
    final_spp[row.sampler] = row.spp, passes[row.sampler] = row.pass;
  }
  for (const char* k : {"bound", "uniform"}) {
    INFO(k);
    // Each ran to the budget, or ended short of it in a last pass cut to the time left (the machine sped up by more
    // than the quarter a cut pass adds: render.cpp; it happened under load). A cut pass is shorter than scheduled.
    const bool cut = final_spp[k] - before_spp[k] < pass_size(passes[k] - 1, before_spp[k], 16 * 12);
    CHECK((final_seconds[k] >= 0.25 || cut));
  }
  CHECK(slurp(out + "/summary.md").find("Equal time: 0.25 s") != std::string::npos);
  // The last column is the written image's relMSE: its last pass's (the relMSE column is at exactly 0.25 s).
  auto table = read_summary_table(slurp(out + "/summary.md"));
  for (const char* k : {"bound", "uniform"}) {
    REQUIRE(table[k].size() == 8);
    CHECK(std::stod(table[k][7]) == Approx(final_relmse[k]).epsilon(1e-4));
    CHECK(std::stod(table[k][7]) == Approx(compute_error(read_image(out + "/" + k + ".exr"), read_image(s.ref)).relmse).epsilon(1e-4));
  }
}

TEST_CASE("bad compare invocations exit 2 or 3 and write nothing", "[compare]") {
  compare_scene s;
  std::string out = s.dir / "out";
  std::string base = "compare " + s.json + " --out " + out + " --quiet ";
  struct bad_case {
    std::string args;
    int status;
    std::string expect;
  };
  REQUIRE(run_bayeslight("render " + s.json + " --spp 1 --width 8 --height 6 -o " + (s.dir / "small.exr") + " --quiet")
              .status == 0);
  std::vector<bad_case> cases = {
      {base + "--reference " + s.ref + " --spp 2 --samplers uniform,nosuch", 2, "uniform | power"},
      {base + "--spp 2 --samplers uniform", 2, "--reference"},
      {base + "--reference " + s.ref + " --spp 2 --time 1 --samplers uniform", 2, "--time"},
      {base + "--reference " + s.ref + " --samplers uniform", 2, "--time and --spp"},
      {base + "--reference " + s.ref + " --spp 2", 2, "--samplers"},
      {base + "--reference " + s.ref + " --spp 2 --samplers uniform,uniform", 2, "twice"},
      {base + "--reference " + s.ref + " --spp 2 --samplers uniform,,power", 2, "empty name"},
      {base + "--reference " + s.ref + " --spp 2 --samplers uniform,", 2, "empty name"},
      {base + "--reference " + s.ref + " --spp 2 --samplers \"\"", 2, "empty name"},
      {base + "--reference " + s.ref + " --spp 2 --samplers \"uniform, \"", 2, "empty name"},
      {base + "--reference " + s.ref + " --spp 2 --samplers \"uniform, Uniform\"", 2, "unknown sampler \"Uniform\""},
      {base + "--reference " + s.ref + " --spp 2 --samplers uniform --runs 0", 2, "--runs"},
      {base + "--reference " + s.ref + " --spp 2 --samplers uniform --frames 2", 2, "--frames"},
      {"compare " + s.json + " --reference " + s.ref + " --spp 2 --samplers uniform", 2, "--out"},
      {base + "--reference " + (s.dir / "small.exr") + " --spp 2 --samplers uniform", 3, "8x6"},
      {base + "--reference " + (s.dir / "missing.exr") + " --spp 2 --samplers uniform", 3, "missing.exr"},
      {"compare " + (s.dir / "nosuch.json") + " --out " + out + " --reference " + s.ref + " --spp 2 --samplers uniform",
       3, "nosuch.json"},
  };
  for (const bad_case& c : cases) {
    run_result r = run_bayeslight(c.args);
    INFO(c.args << "\n" << r.output);
    CHECK(r.status == c.status);
    CHECK(r.output.find(c.expect) != std::string::npos);
    CHECK(!std::filesystem::exists(out));
  }
  // An output name taken by a directory is refused before any render (it failed after all of them, leaving the
  // images without the curves and summary).
  for (const char* taken : {"curves.csv", "bvh.exr", "uniform_error.png"}) {
    std::string out2 = s.dir / "out2";
    std::filesystem::remove_all(out2);
    std::filesystem::create_directories(std::filesystem::path(out2) / taken);
    run_result r = run_bayeslight("compare " + s.json + " --out " + out2 + " --quiet --reference " + s.ref +
                                  " --spp 2 --samplers uniform,bvh");
    INFO(taken << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find(std::string(taken) + ": is a directory") != std::string::npos);
    CHECK(!std::filesystem::exists(std::filesystem::path(out2) / "uniform.exr"));
  }
}

TEST_CASE("time to reach a target error interpolates log-log between passes", "[compare]") {
  // relMSE = 1 / t exactly: the log-log interpolation recovers t = 1 / target between any two passes.
  std::vector<double> t = {1, 2, 4, 8}, e = {1, 0.5, 0.25, 0.125};
  CHECK(time_to_reach(t, e, 0.3) == Approx(1 / 0.3).epsilon(1e-12));
  CHECK(time_to_reach(t, e, 0.125) == Approx(8).epsilon(1e-12));
  CHECK(time_to_reach(t, e, 2.0) == 1);       // already reached by the first pass
  CHECK(time_to_reach(t, e, 0.1) == -1);      // never reached
  CHECK(time_to_reach({}, {}, 0.1) == -1);
  // A dip below the target that rises again does not count: the curve must stay at or below it.
  CHECK(time_to_reach({1, 2, 4}, {1, 0.2, 0.6}, 0.5) == -1);
  CHECK(time_to_reach({1, 2, 4, 8}, {1, 0.2, 0.6, 0.3}, 0.5) == Approx(std::exp(std::log(4.0) + std::log(5.0 / 6.0) *
                                                                                   std::log(2.0) / std::log(0.5))));
}

TEST_CASE("relMSE at a time interpolates log-log between the passes around it", "[compare]") {
  auto log_of = [](std::vector<std::pair<double, double>> points) {
    std::vector<pass_record> log;
    for (auto [t, e] : points) {
      pass_record p;
      p.seconds = t;
      p.error.relmse = e;
      log.push_back(p);
    }
    return log;
  };
  std::vector<pass_record> log = log_of({{1, 1}, {2, 0.5}, {4, 0.25}});
  CHECK(relmse_at_time(log, 3) == Approx(1 / 3.0).epsilon(1e-12));  // relMSE = 1 / t
  CHECK(relmse_at_time(log, 0.5) == 1);                            // before the first pass: the first
  CHECK(relmse_at_time(log, 9) == 0.25);                           // after the last: the last
  // A pass with no error at all (it matched the reference): linear, not the later pass's value.
  CHECK(relmse_at_time(log_of({{1, 0}, {3, 0.2}}), 2) == Approx(0.1));
  CHECK(relmse_at_time(log_of({{1, 0}, {3, 0.2}}), 1.5) == Approx(0.05));  // (a quarter of the way: 0.05, not 0.15)
  CHECK(relmse_at_time(log_of({{1, 0.2}, {3, 0}}), 1.5) == Approx(0.15));
}

TEST_CASE("at equal spp the first sampler reaches its own mean relMSE at its own mean time", "[compare]") {
  // Three runs of one pass whose mean of sums, (a + b + c) / 3, lies one ulp above the sum of means a/3 + b/3 + c/3:
  // the curve's last point missed the target it defines, and the table showed no time for the baseline.
  compare_data d;
  d.samplers.resize(2);
  const double e[3] = {0.006551, 0.007908, 0.001029};
  REQUIRE((e[0] + e[1] + e[2]) / 3 > e[0] / 3 + e[1] / 3 + e[2] / 3);
  for (compare_sampler& cs : d.samplers)
    for (int r = 0; r < 3; r++) {
      compare_run run;
      run.spp = 2;
      pass_record p;
      p.seconds = 1.0 + r;
      p.has_error = true;
      p.error.relmse = &cs == &d.samplers[0] ? e[r] : e[r] / 2;
      run.log.push_back(p);
      cs.runs.push_back(run);
    }
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 2);
  CHECK(st[0].time_to_target == Approx(2.0));
  CHECK(st[1].time_to_target == Approx(2.0));  // (its only point is below the target: reached at its first pass)
}

TEST_CASE("at equal spp the speed-up is the ratio of relMSE times seconds", "[compare]") {
  // The second sampler: the same relMSE in half the time, twice the efficiency; the third: a quarter of the relMSE
  // in twice the time, also twice.
  compare_data d;
  d.samplers.resize(3);
  const double seconds[3] = {2, 1, 4}, relmse[3] = {0.1, 0.1, 0.025};
  for (size_t i = 0; i < 3; i++) {
    compare_run run;
    run.spp = 4;
    pass_record p;
    p.pass = 1;
    p.spp = 4;
    p.seconds = seconds[i];
    p.has_error = true;
    p.error.relmse = relmse[i];
    run.log.push_back(p);
    d.samplers[i].runs.push_back(run);
  }
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 3);
  CHECK(st[0].speedup == Approx(1));
  CHECK(st[1].speedup == Approx(2));
  CHECK(st[2].speedup == Approx(2));
}

// A run of one pass per time in `times` (seconds), each with relMSE c / t.
static compare_run run_of(const std::vector<double>& times, double c) {
  compare_run run;
  run.spp = int(times.size());
  for (double t : times) {
    pass_record p;
    p.seconds = t;
    p.has_error = true;
    p.error.relmse = c / t;
    run.log.push_back(p);
  }
  return run;
}

TEST_CASE("an interrupted equal-time comparison times the first sampler at its last pass, not at the budget",
          "[compare]") {
  compare_data d;
  d.samplers.resize(1);
  d.equal_time = true;
  d.time_budget = 3;
  d.signal = 2;  // SIGINT at 1.5 s: the run's passes end at 0.5, 1.0 and 1.48 s
  d.samplers[0].runs.push_back(run_of({0.5, 1.0, 1.48}, 0.1));
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 1);
  CHECK(st[0].relmse == Approx(0.1 / 1.48));
  CHECK(st[0].time_to_target == Approx(1.48));
  d.signal = 0;  // a complete run ends with the first pass past the budget: reached at the budget
  d.samplers[0].runs[0].log.back().seconds = 3.2;
  CHECK(comparison_stats(d)[0].time_to_target == Approx(3.0));
}

TEST_CASE("at equal time the mean curve averages runs at common times", "[compare]") {
  // Averaged by pass index, a fast run's pass at 0.53 s was averaged with a slow run's at 0.84 s, and a run that had
  // ended was held at its last value (a review). Two runs of relMSE 1/t: the mean at any time is 1/t too.
  compare_data d;
  d.samplers.resize(1);
  d.equal_time = true;
  d.time_budget = 2;
  d.samplers[0].runs = {run_of({0.2, 0.5, 1.0, 2.2}, 1), run_of({0.4, 1.5, 2.1, 2.5}, 1)};
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 1);
  // From the later first pass (0.4 s) to the earlier last one (2.2 s).
  CHECK(st[0].curve_seconds == std::vector<double>{0.4, 0.5, 1.0, 1.5, 2.1, 2.2});
  REQUIRE(st[0].curve_relmse.size() == 6);
  for (size_t i = 0; i < 6; i++) CHECK(st[0].curve_relmse[i] == Approx(1 / st[0].curve_seconds[i]).epsilon(1e-12));
  CHECK(st[0].seconds == Approx((2.2 + 2.5) / 2));  // the runs' mean render time
  CHECK(st[0].relmse == Approx(0.5).epsilon(1e-12));
}

// An equal-time comparison (2 s) that SIGINT stopped during the second sampler, whose passes end at `second`; the
// first ran to the budget. Both samplers have the same error at the same time.
static compare_data interrupted_comparison(const std::vector<double>& second) {
  compare_data d;
  d.samplers.resize(2);
  d.equal_time = true;
  d.time_budget = 2;
  d.signal = 2;
  d.samplers[0].runs.push_back(run_of({0.25, 0.5, 1.0, 2.1}, 0.1));
  d.samplers[1].runs.push_back(run_of(second, 0.1));
  return d;
}

TEST_CASE("an interrupted equal-time comparison compares the samplers where the shortest run ended", "[compare]") {
  // SIGINT during the second sampler: the first ran to the 2 s budget, the second stopped at 0.88 s. The speed-up
  // compared the first's error at 2 s with the second's at 0.88 s (0.65 in a review, 0.99 at a common time).
  compare_data d = interrupted_comparison({0.3, 0.6, 0.88});
  CHECK(comparison_time(d) == 0.88);
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 2);
  CHECK(st[0].relmse == Approx(0.1 / 0.88).epsilon(1e-9));
  CHECK(st[1].speedup == Approx(1).epsilon(1e-9));
  CHECK(st[0].time_to_target == Approx(0.88));
  compare_params p;
  p.samplers = {sampler_kind::uniform, sampler_kind::bayes};
  p.render.time_budget = 2;
  CHECK(comparison_summary(d, p).find("compares the samplers at 0.88 s") != std::string::npos);
  d.signal = 0;  // complete: at the budget
  CHECK(comparison_time(d) == 2);
}

TEST_CASE("an interrupted comparison whose shortest run ended with its first pass compares there", "[compare]") {
  // The second sampler's only pass ends at 0.6 s, the comparison time: its error is known there, not later.
  compare_data d = interrupted_comparison({0.6});
  REQUIRE(comparison_time(d) == 0.6);
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 2);
  CHECK(!st[0].before_first_pass);
  CHECK(!st[1].before_first_pass);
  CHECK(st[1].relmse == Approx(0.1 / 0.6));
  CHECK(st[1].speedup == Approx(1).epsilon(1e-9));
  compare_params p;
  p.samplers = {sampler_kind::uniform, sampler_kind::bayes};
  p.render.time_budget = 2;
  CHECK(comparison_summary(d, p).find("ends before the first pass") == std::string::npos);
}

TEST_CASE("the image relMSE of an equal-time comparison is run 1's last pass", "[compare]") {
  // `<sampler>.exr` is run 1's render: the column gives its error, whichever run ends last or is listed last.
  compare_data d;
  d.samplers.resize(1);
  d.equal_time = true;
  d.time_budget = 1;
  compare_run second = run_of({0.4, 1.1}, 0.2), first = run_of({0.5, 1.2}, 0.1);
  second.run = 2;
  first.run = 1;
  d.samplers[0].runs = {first, second};
  CHECK(comparison_stats(d)[0].image_relmse == Approx(0.1 / 1.2));
  d.samplers[0].runs = {second, first};
  CHECK(comparison_stats(d)[0].image_relmse == Approx(0.1 / 1.2));
}

TEST_CASE("an equal-time comparison shorter than a first pass gives no speed-up against that sampler", "[compare]") {
  compare_data d;
  d.samplers.resize(3);
  d.equal_time = true;
  d.time_budget = 0.001;  // passes end at 0.84 ms (first sampler, then 1.5 ms), 2.4 ms (second), 0.5 ms (third)
  std::vector<std::vector<double>> times = {{0.00084, 0.0015}, {0.0024}, {0.0005, 0.0011}};
  for (size_t i = 0; i < 3; i++) {
    compare_run run;
    run.spp = 1;
    for (double t : times[i]) {
      pass_record p;
      p.seconds = t;
      p.has_error = true;
      p.error.relmse = 1e-4 / t;
      run.log.push_back(p);
    }
    d.samplers[i].runs.push_back(run);
  }
  d.samplers[0].kind = sampler_kind::uniform;
  d.samplers[1].kind = sampler_kind::power;
  d.samplers[2].kind = sampler_kind::bound;
  std::vector<compare_stats> st = comparison_stats(d);
  REQUIRE(st.size() == 3);
  CHECK(!st[0].before_first_pass);
  CHECK(st[1].before_first_pass);
  CHECK(std::isnan(st[1].speedup));
  CHECK(st[2].speedup == Approx(1).epsilon(1e-9));
  compare_params p;
  p.samplers = {sampler_kind::uniform, sampler_kind::power, sampler_kind::bound};
  p.render.time_budget = 0.001;
  CHECK(comparison_summary(d, p).find("ends before the first pass of power") != std::string::npos);
  // The first sampler's own first pass ending after the comparison time: it reached its error there, not sooner.
  d.time_budget = 0.0005;
  st = comparison_stats(d);
  CHECK(st[0].before_first_pass);
  CHECK(st[0].time_to_target == Approx(0.00084));
}

TEST_CASE("the plot writer escapes labels and draws one path per series", "[compare]") {
  plot_series a{"a<b>&\"c\"", {0.01, 0.1, 1}, {1, 0.1, 0.01}};
  plot_series b{"second", {0.0, -1, 0.5, 2}, {1, 1, 0.2, NAN}};  // only (0.5, 0.2) can be placed on log axes
  loglog_plot_params p;
  p.title = "t & t";
  std::string svg = loglog_plot_svg({a, b}, p);
  CHECK(xml_problem(svg) == "");
  CHECK(count_of(svg, "<path") == 2);
  CHECK(svg.find("a&lt;b&gt;&amp;&quot;c&quot;") != std::string::npos);
  CHECK(svg.find("stroke-dasharray") != std::string::npos);
  CHECK(plot_color(0) != plot_color(1));
  CHECK(plot_color(12) != plot_color(13));
  CHECK(plot_color(12).size() == 7);
  // Nothing plottable still gives a valid document (axes, legend, no paths).
  std::string empty = loglog_plot_svg({plot_series{"none", {}, {}}}, p);
  CHECK(xml_problem(empty) == "");
  CHECK(count_of(empty, "<path") == 0);
  // The checker itself rejects malformed documents.
  CHECK(xml_problem("<svg><g></svg>") != "");
  CHECK(xml_problem("<svg a=1></svg>") != "");
  CHECK(xml_problem("<svg>a & b</svg>") != "");
}

TEST_CASE("the error ramp spans viridis over a fixed logarithmic range", "[compare]") {
  std::array<uint8_t, 3> lo = viridis_srgb8(0), hi = viridis_srgb8(1), nan = viridis_srgb8(NAN);
  CHECK((lo == std::array<uint8_t, 3>{0x44, 0x01, 0x54}));
  CHECK((hi == std::array<uint8_t, 3>{0xfd, 0xe7, 0x25}));
  CHECK(nan == hi);
  CHECK(viridis_srgb8(-1) == lo);
  CHECK(viridis_srgb8(7) == hi);
  image_data x, r;
  x.width = r.width = 2;
  x.height = r.height = 1;
  r.pixels = {1, 1, 1, 0, 0, 0};
  x.pixels = {1.5f, 1.5f, 1.5f, 0.05f, 0, 0.1f};
  std::vector<float> err = relative_error_map(x, r);
  REQUIRE(err.size() == 2);
  CHECK(err[0] == Approx(0.5 / 1.1));
  CHECK(err[1] == Approx((0.5 + 0 + 1.0) / 3));
  std::string png = encode_error_png(x, r, error_image_params{});
  CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
}

TEST_CASE("the error image maps min_error to max_error logarithmically onto the ramp", "[compare]") {
  // Pixels of relative error min_error, the geometric mean of the range and max_error: the ramp's bottom, middle
  // (stop 4 of 8) and top, for the default range and another one.
  for (const error_image_params& params : {error_image_params{}, error_image_params{0.01f, 10.0f}}) {
    const double lo = params.min_error, hi = params.max_error, e[3] = {lo, std::sqrt(lo * hi), hi};
    image_data x, r;
    x.width = r.width = 3;
    x.height = r.height = 1;
    r.pixels.assign(9, 1.0f);
    for (double v : e)
      for (int c = 0; c < 3; c++) x.pixels.push_back(float(1 + 1.1 * v));  // |x - r| / (|r| + 0.1) = v
    std::string png = encode_error_png(x, r, params);
    int w = 0, h = 0, n = 0;
    unsigned char* px =
        stbi_load_from_memory(reinterpret_cast<const unsigned char*>(png.data()), int(png.size()), &w, &h, &n, 3);
    REQUIRE(px != nullptr);
    CHECK(w == 3);
    CHECK(h == 1);
    const float t[3] = {0, 0.5f, 1};
    for (int i = 0; i < 3; i++) {
      const std::array<uint8_t, 3> want = viridis_srgb8(t[i]);
      INFO("range " << lo << " to " << hi << ", error " << e[i]);
      for (int c = 0; c < 3; c++) CHECK(std::abs(int(px[3 * i + c]) - int(want[size_t(c)])) <= 2);
    }
    stbi_image_free(px);
  }
}

namespace {

// The coordinates of the first <path>'s points ("M x y L x y ...") in an SVG document.
std::vector<std::pair<double, double>> first_path_points(const std::string& svg) {
  std::vector<std::pair<double, double>> points;
  size_t at = svg.find("<path d=\"");
  if (at == std::string::npos) return points;
  std::string d = svg.substr(at + 9, svg.find('"', at + 9) - at - 9);
  for (char& c : d)
    if (c == 'M' || c == 'L') c = ' ';
  std::istringstream in(d);
  for (double x, y; in >> x >> y;) points.push_back({x, y});
  return points;
}

}  // namespace

TEST_CASE("the plot puts larger values higher up and data on one decade line on finite axes", "[compare]") {
  loglog_plot_params p;
  // Time to the right, relMSE falling: the second point is to the right of and below the first (SVG's y grows
  // downward).
  std::vector<std::pair<double, double>> pts = first_path_points(loglog_plot_svg({{"a", {0.1, 10}, {1, 0.01}}}, p));
  REQUIRE(pts.size() == 2);
  CHECK(pts[1].first > pts[0].first);
  CHECK(pts[1].second > pts[0].second);
  // Every point at exact powers of ten (one pass at 1 s of relMSE 0.01): each axis still spans a decade, and every
  // coordinate is a number.
  for (const plot_series& one : {plot_series{"one", {1}, {0.01}}, plot_series{"same", {1, 1}, {0.01, 0.01}}}) {
    std::string svg = loglog_plot_svg({one}, p);
    INFO(svg);
    CHECK(xml_problem(svg) == "");
    CHECK(svg.find("nan") == std::string::npos);
    CHECK(svg.find("inf") == std::string::npos);
    pts = first_path_points(svg);
    REQUIRE(!pts.empty());
    for (auto [x, y] : pts) CHECK((std::isfinite(x) && std::isfinite(y)));
  }
}

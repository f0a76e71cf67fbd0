// ViSP's model-based trackers (moving edges; moving edges with KLT points) on one view, as the real-photo bench's
// peer. Built by bench/peer_env.py against the system's ViSP (Debian: libvisp-mbt-dev) and run in a process of its
// own; it knows nothing of videocal.
//
// Reads JSON on stdin: {"image": path, "K": 3x3, "vertices": (n, 3) mm, "faces": (m, 3), "views": [{"rvec",
// "tvec" (mm)}] (the priors), "iterations": n, "klt": bool}. Writes one line of JSON: per prior, the pose it ends
// at (rvec, tvec mm), whether ViSP returned one, and the seconds the tracking took (the model's loading excluded).
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpIoTools.h>
#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpTranslationVector.h>
#include <visp3/io/vpImageIo.h>
#include <visp3/mbt/vpMbEdgeKltTracker.h>
#include <visp3/mbt/vpMbEdgeTracker.h>

using json = nlohmann::json;

namespace {

// The mesh as ViSP's own model format (.cao, version 1: points, then faces by their points), in metres.
void write_cao(const std::string &path, const json &vertices, const json &faces) {
  std::ofstream out(path);
  out << "V1\n" << vertices.size() << "\n";
  for (const auto &v : vertices)
    out << v[0].get<double>() / 1000.0 << " " << v[1].get<double>() / 1000.0 << " " << v[2].get<double>() / 1000.0
        << "\n";
  out << "0\n0\n" << faces.size() << "\n";
  for (const auto &f : faces)
    out << "3 " << f[0].get<int>() << " " << f[1].get<int>() << " " << f[2].get<int>() << "\n";
  out << "0\n0\n";
}

vpMe moving_edges() {
  // ViSP's tutorial settings for the moving edges (tutorial-mb-edge-tracker)
  vpMe me;
  me.setMaskSize(5);
  me.setMaskNumber(180);
  me.setRange(8);
  me.setThreshold(10000);
  me.setMu1(0.5);
  me.setMu2(0.5);
  me.setSampleStep(4);
  return me;
}

template <class Tracker> void configure(Tracker &tracker, const vpCameraParameters &cam, const std::string &cao) {
  tracker.setMovingEdge(moving_edges());
  tracker.setCameraParameters(cam);
  tracker.setAngleAppear(vpMath::rad(70));
  tracker.setAngleDisappear(vpMath::rad(80));
  tracker.setNearClippingDistance(0.05);
  tracker.setFarClippingDistance(5.0);
  tracker.setClipping(tracker.getClipping() | vpMbtPolygon::FOV_CLIPPING);
  tracker.loadModel(cao);
}

void configure_klt(vpMbEdgeKltTracker &tracker) {
  // ViSP's tutorial settings for the KLT points (tutorial-mb-hybrid-tracker)
  vpKltOpencv klt;
  klt.setMaxFeatures(300);
  klt.setWindowSize(5);
  klt.setQuality(0.015);
  klt.setMinDistance(8);
  klt.setHarrisFreeParameter(0.01);
  klt.setBlockSize(3);
  klt.setPyramidLevels(3);
  tracker.setKltOpencv(klt);
  tracker.setKltMaskBorder(5);
}

} // namespace

int main() {
  json request;
  try {
    std::cin >> request;
  } catch (const std::exception &e) {
    std::cerr << "visp_tracker: cannot read the request: " << e.what() << "\n";
    return 2;
  }
  vpImage<unsigned char> I;
  try {
    vpImageIo::read(I, request["image"].get<std::string>());
  } catch (const vpException &e) {
    std::cerr << "visp_tracker: cannot read the image: " << e.getMessage() << "\n";
    return 2;
  }
  const json &K = request["K"];
  vpCameraParameters cam(K[0][0].get<double>(), K[1][1].get<double>(), K[0][2].get<double>(), K[1][2].get<double>());
  char folder[] = "/tmp/visp_trackerXXXXXX";
  if (mkdtemp(folder) == nullptr) {
    std::cerr << "visp_tracker: cannot make a temporary folder\n";
    return 2;
  }
  const std::string cao = std::string(folder) + "/model.cao";
  write_cao(cao, request["vertices"], request["faces"]);
  const int iterations = request.value("iterations", 10);
  const bool with_klt = request.value("klt", false);
  json rows = json::array();
  for (const auto &view : request["views"]) {
    vpThetaUVector turn(view["rvec"][0].get<double>(), view["rvec"][1].get<double>(), view["rvec"][2].get<double>());
    vpTranslationVector move(view["tvec"][0].get<double>() / 1000.0, view["tvec"][1].get<double>() / 1000.0,
                             view["tvec"][2].get<double>() / 1000.0);
    vpHomogeneousMatrix cMo(move, turn);
    json row = {{"ok", false}};
    const auto t0 = std::chrono::steady_clock::now();
    try {
      if (with_klt) {
        vpMbEdgeKltTracker tracker;
        configure(tracker, cam, cao);
        configure_klt(tracker);
        tracker.initFromPose(I, cMo);
        for (int k = 0; k < iterations; ++k)
          tracker.track(I);
        tracker.getPose(cMo);
      } else {
        vpMbEdgeTracker tracker;
        configure(tracker, cam, cao);
        tracker.initFromPose(I, cMo);
        for (int k = 0; k < iterations; ++k)
          tracker.track(I);
        tracker.getPose(cMo);
      }
      row["ok"] = true;
    } catch (const vpException &e) {
      row["error"] = e.getMessage();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    vpThetaUVector r(cMo.getRotationMatrix());
    vpTranslationVector t = cMo.getTranslationVector();
    row["rvec"] = {r[0], r[1], r[2]};
    row["tvec"] = {t[0] * 1000.0, t[1] * 1000.0, t[2] * 1000.0};
    row["seconds"] = seconds;
    rows.push_back(row);
  }
  std::remove(cao.c_str());
  vpIoTools::remove(folder);
  std::cout << rows.dump() << "\n";
  return 0;
}
